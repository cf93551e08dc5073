// `phiq check SCENE [--json] [--time T]`: the scene's counts (coordinates, equations, non-zeros), the assembly from
// its rough placement and the rank analysis there (dof, redundant and conflicting constraints), and its real
// assembly modes with the one the placement is in (mode_count.hpp), as text or JSON.
#include <cstdio>
#include <iostream>
#include <memory>
#include <optional>

#include <nlohmann/json.hpp>

#include "command_line.hpp"
#include "command_support.hpp"
#include "commands.hpp"
#include "mode_count.hpp"
#include "phiq/applied_loads.hpp"
#include "phiq/phiq.hpp"

namespace phiq::tools {

namespace {

// "motor: joint crank_hinge from x_a = [1, 0, 0] (default) to x_b = [0, 1, 0] (stated)": where a driven joint
// angle is measured from, in the sides' body frames.
std::string joint_angle_line(const phiq::JointAngleReference& r) {
  auto vec = [](const std::array<double, 3>& v) {
    return "[" + phiq::shortest(v[0]) + ", " + phiq::shortest(v[1]) + ", " + phiq::shortest(v[2]) + "]";
  };
  auto how = [](bool stated) { return stated ? " (stated)" : " (default: state `ref` to choose)"; };
  return r.driver + ": joint " + r.joint + " from x_a = " + vec(r.ref_a) + how(r.stated_a) +
         " to x_b = " + vec(r.ref_b) + how(r.stated_b) + ", in the sides' body frames";
}

// Six significant digits: what a person checks a mass against (--json gives every digit).
std::string g6(double v) {
  char b[32];
  std::snprintf(b, sizeof b, "%.6g", v);
  return b;
}

// What presses a bearing (BearingFriction): a journal's r (|F_r| + |M_b| / a) + r_a |F_a|, a slide's |F_r| + |M| / a.
std::string bearing_load_text(const phiq::BearingFriction& b) {
  const std::string arm =
      b.moment_arm > 0.0 ? " + |M" + std::string(b.slide ? "" : "_b") + "| / " + g6(b.moment_arm) + " m" : "";
  if (b.slide) return "|F_r|" + arm;
  return g6(b.radius) + " m x " + (arm.empty() ? "|F_r|" : "(|F_r|" + arm + ")") +
         (b.thrust_radius != 0.0 ? " + " + g6(b.thrust_radius) + " m x |F_a|" : "");
}

const char* mass_source(const phiq::Part& p) {
  switch (p.mass_source) {
    case phiq::MassSource::kStated:
      return "stated";
    case phiq::MassSource::kDensity:
      return "density";
    case phiq::MassSource::kNone:
      break;
  }
  return "none";
}

// The inertia as a user reads it: planar Izz; spatial [Ixx, Iyy, Izz, Ixy, Ixz, Iyz] (body axes, about the centre).
std::string inertia_text(const phiq::Part& p, int dimension) {
  const auto& I = p.mass.inertia;
  if (dimension == 2) return "Izz " + g6(I[8]);
  return "[Ixx, Iyy, Izz, Ixy, Ixz, Iyz] [" + g6(I[0]) + ", " + g6(I[4]) + ", " + g6(I[8]) + ", " + g6(I[1]) + ", " +
         g6(I[2]) + ", " + g6(I[5]) + "]";
}

// "coupler on body coupler, 1 shape: mass 3.768 kg (from density 7850 kg/m³), centre [0, 0, 0] m, Izz 0.45 kg·m²".
std::string part_line(const phiq::Part& p, int dimension) {
  std::string s = p.name + " on " + (p.body.rfind("frame", 0) == 0 ? p.body : "body " + p.body) + ", " +
                  std::to_string(p.shapes.size()) + (p.shapes.size() == 1 ? " shape" : " shapes");
  if (p.mass_source == phiq::MassSource::kNone) return s + ", no mass";
  const auto& c = p.mass.center;
  s += ": mass " + g6(p.mass.mass) + " kg (" +
       (p.mass_source == phiq::MassSource::kDensity ? "from density " + g6(p.density) + " kg/m³" : "stated") +
       "), centre [" + g6(c.x) + ", " + g6(c.y) + (dimension == 3 ? ", " + g6(c.z) : "") + "] m, " +
       inertia_text(p, dimension) + " kg·m² about the centre";
  return s;
}

// A load's scalar as written: its expression, or its law "of" it.
std::string load_value_text(const phiq::LoadValue& v) {
  if (!v.expr) return "0";
  return v.law.has_value() ? v.law.description() + " of " + v.expr->text() : v.expr->text();
}

std::string load_vector_text(const std::array<phiq::LoadValue, 3>& c, phiq::LoadAxes axes, int dimension) {
  std::string s = "[";
  for (int k = 0; k < dimension; ++k) s += (k ? ", " : "") + load_value_text(c[static_cast<std::size_t>(k)]);
  return s + "] (" + (axes == phiq::LoadAxes::kPart ? "part" : "world") + " axes)";
}

// One line per applied load: what it is, what it acts on and its values as written (expressions, rates der(),
// laws), so that a scene's loads can be read back as phiq took them: "force 'drag' on part 'piston' at [0, 0]:
// [-c1*der(xB), 0] (world axes)".
std::vector<std::string> load_lines(const phiq::AppliedLoads& a, int dimension) {
  std::vector<std::string> out;
  auto at = [&](const phiq::kin3::V3& v) {
    return "[" + g6(v.x) + ", " + g6(v.y) + (dimension == 3 ? ", " + g6(v.z) : "") + "]";
  };
  for (const phiq::AppliedForce& f : a.forces)
    out.push_back("force '" + f.name + "' on '" + f.part + "' at " + at(f.at) + ": " +
                  load_vector_text(f.components, f.axes, dimension) + " N");
  for (const phiq::AppliedTorque& t : a.torques)
    out.push_back("torque '" + t.name + "' on '" + t.part + "': " +
                  (dimension == 3 ? load_vector_text(t.components, t.axes, 3) : load_value_text(t.components[2])) +
                  " N·m");
  auto elastic = [](double k, const phiq::MotionLaw& law) { return law.has_value() ? law.description() : g6(k); };
  auto dry = [](double f) { return f != 0.0 ? ", friction " + g6(f) : std::string(); };  // (only where it has one)
  for (const phiq::LinearSpring& s : a.springs)
    out.push_back("spring '" + s.name + "' between '" + s.a.part + "' " + at(s.a.at) + " and '" + s.b.part + "' " +
                  at(s.b.at) + ": stiffness " + elastic(s.stiffness, s.law) + ", free length " + g6(s.free_length) +
                  ", damping " + g6(s.damping) + dry(s.friction) + ", preload " + g6(s.preload) + ", tension " +
                  load_value_text(s.tension));
  for (const phiq::TorsionalSpring& s : a.torsional_springs)
    out.push_back("torsional spring '" + s.name + "' on " +
                  (s.angle ? "'" + s.angle->text() + "'" : "joint '" + s.joint->name + "'") + ": stiffness " +
                  elastic(s.stiffness, s.law) + ", free angle " + g6(s.free_angle) + ", damping " + g6(s.damping) +
                  dry(s.friction) + (s.inertia != 0.0 ? ", inertia " + g6(s.inertia) : "") + ", moment " +
                  load_value_text(s.moment) +
                  (s.bearing ? ", bearing '" + s.bearing->joint + "' friction " + g6(s.bearing->coefficient) + " x (" +
                                   bearing_load_text(*s.bearing) + ")"
                             : ""));
  for (const phiq::GearLoss& l : a.gear_losses)
    out.push_back("gear loss of '" + l.gear + "': " +
                  (l.friction > 0.0
                       ? "worm friction " + g6(l.friction)
                       : "efficiency " + g6(l.efficiency) +
                             (l.reverse_efficiency != l.efficiency ? ", reverse " + g6(l.reverse_efficiency) : "")));
  return out;
}

nlohmann::ordered_json parts_json(const phiq::Scene& scene) {
  auto parts = nlohmann::ordered_json::array();
  for (const phiq::Part& p : scene.parts) {
    const auto& I = p.mass.inertia;
    parts.push_back({{"name", p.name},
                     {"body", p.body},
                     {"shapes", p.shapes.size()},
                     {"mass_source", mass_source(p)},
                     {"mass", p.mass.mass},
                     {"center_of_mass", {p.mass.center.x, p.mass.center.y, p.mass.center.z}},
                     {"inertia", {{I[0], I[1], I[2]}, {I[3], I[4], I[5]}, {I[6], I[7], I[8]}}}});
  }
  return parts;
}

int cmd_check(const std::string& scene_arg, bool json, std::optional<double> at, const std::vector<std::string>& sets) {
  const std::string scene_path = scene_label(scene_arg);  // "-": standard input, named <stdin>
  std::optional<phiq::Scene> loaded = load_or_report(scene_arg, sets);
  if (!loaded) return 2;
  const phiq::Scene& scene = *loaded;
  const phiq::Model& model = *scene.model;
  int drivers = 0;
  for (const auto& c : model.constraints()) drivers += c.depends_on_time ? c.rows : 0;

  // Minimum-norm assembly from the rough placement, with the rank analysis at the assembled position (or where it
  // stopped): works for square, redundant and under-driven models alike.
  Eigen::VectorXd q = model.initial_positions();
  phiq::AssemblySummary as;
  const double t0 = at ? *at : scene.sweep.t_begin;  // rank belongs to a configuration: `--time` picks another
  (void)phiq::assemble(                              // its status is as.status, read below
      model, t0, assembly_options(scene), q, &as);
  const bool ok = as.status == phiq::SolveStatus::kSuccess;
  const bool analysed =
      as.rank.coordinates == model.num_coordinates() && as.status != phiq::SolveStatus::kOutsideTimeDomain;
  const phiq::RankReport& rk = as.rank;
  // inconsistent names its conflicts; not consistent without any is "not known" (the independent equations
  // themselves do not hold: AssemblySummary::consistent)
  const bool consistency_known = as.consistent || !as.conflicts.empty();
  // the real assembly modes at t0 and the one the placement assembled into (within mode_count.hpp's bound)
  ModeCount modes;
  if (analysed) {
    modes = count_modes(scene, t0, ok ? &q : nullptr, 0);
  } else {
    modes.state = ModeCount::State::kNotAvailable, modes.time = t0, modes.reason = as.message;
  }

  if (json) {
    // `phiq check --json`, format version 1 (tools/README.md): one object on standard output.
    nlohmann::ordered_json j;
    j["format"] = phiq::kCheckJsonFormat;
    j["phiq"] = phiq::kVersion;
    j["scene"] = scene_path;
    j["name"] = scene.name;
    j["coordinates"] = model.num_coordinates();
    j["equations"] = model.num_equations();
    j["kinematic_equations"] = model.num_equations() - drivers;
    j["driver_equations"] = drivers;
    j["constraints"] = model.constraints().size();
    j["nonzeros"] = model.jacobian_pattern().nnz();
    j["length_scale"] = model.length_scale();
    j["linear_solver"] = phiq::to_string(model.linear_solver());
    nlohmann::ordered_json a;
    a["time"] = t0;
    a["status"] = phiq::to_string(as.status);
    a["iterations"] = as.iterations;
    a["residual"] = as.residual;
    a["tolerance"] = scene.sweep.assembly.tolerance;
    a["message"] = as.message;
    a["worst"] = nlohmann::ordered_json::array();
    for (const auto& [row, value] : as.worst_rows)
      a["worst"].push_back(
          {{"constraint", model.constraints()[model.constraint_of_row(row)].name}, {"row", row}, {"residual", value}});
    j["assembly"] = a;
    // The redundancy analysis at the assembled position (or where the assembly stopped); null when not run.
    auto or_null = [&](auto v) { return analysed ? nlohmann::ordered_json(v) : nlohmann::ordered_json(); };
    j["rank"] = or_null(rk.rank);
    j["dof"] = or_null(rk.dof);
    j["driven_dof"] = or_null(rk.driven_dof);
    j["grubler"] = rk.grubler ? nlohmann::ordered_json(*rk.grubler) : nlohmann::ordered_json();
    j["redundant"] = rk.redundant;
    j["redundant_rows"] = nlohmann::ordered_json::array();
    for (phiq::Index r : rk.redundant_rows)
      j["redundant_rows"].push_back({{"constraint", model.constraints()[model.constraint_of_row(r)].name},
                                     {"row", r},
                                     {"name", model.row_name(r)}});
    j["consistent"] = consistency_known ? nlohmann::ordered_json(as.consistent) : nlohmann::ordered_json();
    j["conflicts"] = as.conflicts;
    j["rank_tolerance"] = rk.tolerance;
    j["rank_uncertain"] = rk.uncertain;
    j["rank_message"] = rk.message;
    j["joint_angles"] = nlohmann::ordered_json::array();
    for (const phiq::JointAngleReference& r : scene.joint_angles)
      j["joint_angles"].push_back({{"driver", r.driver},
                                   {"joint", r.joint},
                                   {"ref_a", r.ref_a},
                                   {"ref_b", r.ref_b},
                                   {"stated_a", r.stated_a},
                                   {"stated_b", r.stated_b}});
    j["parts"] = parts_json(scene);
    j["modes"] = mode_count_json(modes);
    std::cout << json_text(j, 2) << "\n";
    return ok ? 0 : 1;
  }

  std::cout << "scene         " << scene_path << (scene.name.empty() ? "" : " (" + scene.name + ")") << "\n"
            << "coordinates   " << model.num_coordinates() << "\n"
            << "equations     " << model.num_equations() << " (" << model.num_equations() - drivers << " kinematic, "
            << drivers << " rheonomic)\n"
            << "constraints   " << model.constraints().size() << "\n"
            << "jacobian      " << model.num_equations() << " x " << model.num_coordinates() << ", "
            << model.jacobian_pattern().nnz() << " non-zeros\n"
            << "length scale  " << model.length_scale() << " m\n"
            << "linear solver " << phiq::to_string(model.linear_solver()) << "\n";
  if (!analysed) {
    std::cout << "assembly      not attempted: " << as.message << "\n";
    return 1;
  }
  std::cout << "assembly      " << phiq::to_string(as.status) << " at t = " << phiq::format_time(t0) << " in "
            << as.iterations << " iterations, scaled residual " << scientific(as.residual, 3) << " (tolerance "
            << scientific(scene.sweep.assembly.tolerance, 3) << ")\n"
            << "rank          " << rk.rank << " of " << rk.kinematic_equations << " kinematic equations ("
            << rk.driven_rank << " of " << rk.equations << " with the drivers)\n"
            << "dof           " << rk.dof << " (" << rk.driven_dof << " not driven)\n"
            << "grubler       " << (rk.grubler ? std::to_string(*rk.grubler) : std::string("not defined")) << "\n"
            << "redundant     " << (rk.redundant.empty() ? "none" : joined(rk.redundant)) << "\n"
            << "consistent    "
            << (!consistency_known ? "not known: the independent equations do not hold"
                : as.consistent    ? "yes"
                                   : "no: conflicting " + joined(as.conflicts))
            << "\n";
  for (const phiq::JointAngleReference& r : scene.joint_angles)
    std::cout << "joint angle   " << joint_angle_line(r) << "\n";
  for (const phiq::Part& p : scene.parts) std::cout << "part          " << part_line(p, scene.dimension) << "\n";
  if (scene.loads.applied)
    for (const std::string& l : load_lines(*scene.loads.applied, scene.dimension))
      std::cout << "load          " << l << "\n";
  for (const phiq::OutputLimit& l : scene.sweep.limits)  // (a scene's limits, as the sweep checks them)
    std::cout << "limit         " << l.name << ": " << l.what << " in [" << phiq::significant(l.lo, 10) << ", "
              << phiq::significant(l.hi, 10) << "]\n";
  std::cout << "modes         " << mode_count_text(modes, "the placement") << "\n";
  if (rk.uncertain) std::cout << "uncertain     " << rk.message << "\n";
  if (!ok) std::cout << "diagnosis     " << as.message << "\n";
  return ok ? 0 : 1;
}

}  // namespace

Command register_check(CLI::App& app) {
  struct Args {
    std::string path;
    bool json = false;
    double time = 0.0;
    std::vector<std::string> sets;
  };
  auto a = std::make_shared<Args>();
  CLI::App* check = app.add_subcommand(
      "check",
      "Count coordinates and equations, rank, dof, redundancy; try the assembly; count the real assembly modes");
  check->add_option("scene", a->path, "Scene file (YAML; '-': standard input)")->required();
  check->add_flag("--json", a->json, "Print one JSON object (format: tools/README.md)");
  CLI::Option* at = check->add_option("--time", a->time, "Assemble and analyse at this time instead of time.start")
                        ->check(any_number());
  add_set_option(check, &a->sets);
  return {check, [a, at] {
            return with_stdout_checked(
                cmd_check(a->path, a->json, at->count() ? std::optional<double>(a->time) : std::nullopt, a->sets));
          }};
}

}  // namespace phiq::tools
