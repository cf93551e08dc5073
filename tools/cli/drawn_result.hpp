// What `phiq plot` and `phiq animate` draw: a result of the scene read from a file (CSV or HDF5) and checked to be
// that scene's own, or, given no result, the scene swept here in memory as `phiq run` sweeps it, with the outputs the
// drawing needs added to the scene's (the coordinates it reads, the spatial joints' measures).
#pragma once

#include <string>
#include <vector>

#include "phiq/csv_compare.hpp"
#include "phiq/scene.hpp"

namespace phiq::tools {

// A refusal with the command's exit status: 1 a scene that cannot be swept (as `phiq run`), 2 bad input.
class DrawError : public Error {
 public:
  DrawError(const std::string& message, int status) : Error(message), status_(status) {}
  int status() const { return status_; }

 private:
  int status_;
};

// The result at `path` (HDF5 when it has the signature or an .h5/.hdf5 name, else CSV), checked to be `scene`'s:
// an HDF5 file must record the scene's text and parameter values; the columns of either must be those the scene's
// output writes (dotted or identifier names, `phiq run --names`; plus `--sensitivity` columns of its
// parameters). Identifier names are given back dotted. Throws DrawError (status 2) with one line naming the result
// and the scene: "r.csv: its columns are not the output of s.yaml: no column 'x2'".
CsvTable read_scene_result(const Scene& scene, const std::string& path);

// What a drawing adds to the scene's output when it sweeps the scene itself.
struct DrawnOutputs {
  std::vector<Index> coordinates;  // read by the drawing: their q columns (and q̇ when the scene solves it)
  bool joints = false;             // the angle or distance of every spatial joint that has one (measured_joints())
};

// The coordinates that `slots` read, ascending, each once.
std::vector<Index> coordinates_of(const std::vector<Slot>& slots);

// The measures `output.joints` could list for the scene's spatial joints: a revolute's angle, a prismatic's
// distance, a cylindrical's both, in constraint order; none for a planar scene.
std::vector<OutputJoint> measured_joints(const Scene& scene);

// The scene's sweep run here as `phiq run` runs it (made square, the scene's time grid, solver settings and
// output, on all cores: the same rows to the bit), with `add`'s outputs added, held in memory as the table its
// CSV would read to. Throws DrawError: status 1 with "SCENE: WHY" for a scene that cannot be swept.
CsvTable sweep_scene(const Scene& scene, const DrawnOutputs& add);

}  // namespace phiq::tools
