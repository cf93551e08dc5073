// What an output plan writes (output_plan.hpp), decided with the writers that write it: the coordinates whose
// sensitivity columns are written, which the sweep solves the adjoint form for.
#include "phiq/output_plan.hpp"

#include <algorithm>

#include "phiq/model.hpp"
#include "phiq/natural_joints.hpp"

namespace phiq {

const char* to_string(SensitivityForm form) {
  switch (form) {
    case SensitivityForm::kAuto:
      return "auto";
    case SensitivityForm::kDirect:
      return "direct";
    case SensitivityForm::kAdjoint:
      return "adjoint";
  }
  return "?";
}

std::vector<Index> OutputPlan::sensitivity_outputs() const {
  std::vector<Index> out(coordinate_columns);
  for (const std::vector<Index>* more : {&written_velocities(), &written_accelerations()})
    out.insert(out.end(), more->begin(), more->end());
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return out;
}

std::string OutputEfforts::reaction_name(const Model& model, const OutputReaction& r) const {
  if (r.natural >= 0) return natural->joints.at(static_cast<std::size_t>(r.natural)).name;
  return model.constraints().at(static_cast<std::size_t>(r.constraint)).name;
}

Index effort_values(const OutputEfforts& efforts, std::size_t parameters) {
  return efforts.size() + static_cast<Index>(2 * efforts.constraints.size() * parameters);  // ∂τ/∂p, ∂P/∂p
}

}  // namespace phiq
