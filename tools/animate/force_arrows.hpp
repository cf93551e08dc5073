// `phiq animate --forces SCALE` (HTML): the drivers' efforts and the joints' reactions of a result (the scene's
// output.efforts and output.reactions columns) as arrows at the rows the page keeps, SCALE metres per newton. A
// reaction's force is drawn from its joint's point (the ReactionSite, on the body that carries it), its moment as an
// arc about the point in the plane (radius SCALE·|M| metres per N·m, 270°, the head giving the sense) and as an arrow
// along its axis in space. A driver's effort of an angle is a moment about z drawn as a reaction's, at the first
// joint with a point that shares a coordinate with it (or with a constraint that does: a driven crank's pivot); an
// effort without such a joint, of a length, or of a spatial scene is listed as not drawn (`unplaced`).
#pragma once

#include <Eigen/Core>
#include <nlohmann/json.hpp>

#include <string>
#include <vector>

#include "phiq/csv_compare.hpp"
#include "phiq/scene.hpp"

namespace phiq::tools {

// The viewer's `forces` (viewer.js documents them) for `table`, the result of `scene` read from `result`, at its
// rows `rows` whose positions are `q`; `scale` > 0 in m/N. Throws phiq::Error, one line, for a scene
// that writes neither efforts nor reactions and for a column they need that `table` lacks.
nlohmann::json force_arrows(const Scene& scene, const CsvTable& table, const std::vector<std::size_t>& rows,
                            const std::vector<Eigen::VectorXd>& q, const std::string& result, double scale);

}  // namespace phiq::tools
