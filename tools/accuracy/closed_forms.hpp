// Closed-form kinematics of the mechanisms phiq's accuracy is measured on (`phiq sweep-accuracy`, tools/README.md):
// the seed crank-slider, the seed four-bar (any of its four formulations) and the generated nfourbar and chain3d.
// Derived from the geometry alone (circle intersections and their time derivatives), never from phiq's solver, so
// that they are an independent reference.
#pragma once

#include <memory>
#include <string>
#include <vector>

namespace phiq::tools {

// A quantity and its first two time derivatives.
struct Motion {
  double q = 0.0, v = 0.0, a = 0.0;
};

// The exact motion of a mechanism driven by one angle θ(t) = theta0 + omega·t. Each model coordinate, named as the
// seed scenes and the generator name them, is a sum of terms in the mechanism's link angles (a constant, an angle,
// or a length times the cosine or sine of an angle), so that positions, velocities and accelerations follow from
// the angles' motions by the chain rule.
class ClosedForm {
 public:
  virtual ~ClosedForm() = default;
  // "crank-slider", "fourbar", "nfourbar" or "chain3d", with the parameters in use: "fourbar:L1=1,L2=0.4,...".
  virtual std::string describe() const = 0;
  // Binds the coordinates of a model, in order; afterwards evaluate() fills one entry per bound name. Throws
  // std::invalid_argument naming the first coordinate this mechanism does not have.
  void bind(const std::vector<std::string>& coordinates);
  // How many coordinates are bound.
  std::size_t size() const { return bound_.size(); }
  // Whether bound coordinate j is an angle (compare it modulo 2π).
  bool is_angle(std::size_t j) const { return bound_[j].angle; }
  // Positions, velocities and accelerations of the bound coordinates at time t.
  void evaluate(double t, double* q, double* v, double* a) const;

 protected:
  // One term of a coordinate: coef · f(angle k), f the identity, cos or sin; angle −1 is the constant coef.
  struct Term {
    enum Kind { kConstant, kAngle, kCos, kSin } kind;
    int angle;
    double coef;
  };
  struct Binding {
    std::vector<Term> terms;
    bool angle = false;
  };
  // The terms of coordinate `name`, or false if the mechanism has no such coordinate.
  virtual bool terms_of(const std::string& name, Binding& out) const = 0;
  // Called by bind() before terms_of(): a mechanism whose formulations share names tells them apart here.
  virtual void prepare(const std::vector<std::string>& /*coordinates*/) {}
  // The link angles at time t, with their derivatives.
  virtual void angles(double t, std::vector<Motion>& out) const = 0;

 private:
  std::vector<Binding> bound_;
  mutable std::vector<Motion> angles_;
};

// The worst differences between the rows of a computed motion and a closed form bound to its coordinates:
// positions (angles modulo 2π), velocities and accelerations, over all rows added, each divided by a coordinate
// scale when one is given (e.g. the model's tolerance scales).
class ClosedFormErrors {
 public:
  // `scale`, if not null, has f.size() entries and outlives this object.
  explicit ClosedFormErrors(const ClosedForm& f, const double* scale = nullptr);
  // Adds the row at time t (qd, qdd null when not computed; each has f.size() entries); returns its position error.
  double add(double t, const double* q, const double* qd, const double* qdd);
  double q_error = 0.0, v_error = 0.0, a_error = 0.0;  // worst so far

 private:
  const ClosedForm& f_;
  const double* scale_;
  std::vector<double> rq_, rv_, ra_;  // the closed form at t
};

// Parses "KIND[:NAME=VALUE,...]" (KIND crank-slider, fourbar, nfourbar or chain3d; parameters in describe() order,
// defaults those of models/seed/ and of `phiq generate nfourbar` and `chain3d`). Throws std::invalid_argument for an
// unknown kind or parameter, a value that is not a finite number, or impossible geometry.
std::unique_ptr<ClosedForm> make_closed_form(const std::string& spec);

// The closed form a scene's `name` suggests ("crank_slider_*", "fourbar_*", "nfourbar_*", "chain3d_*"), or "" if
// none.
std::string closed_form_for_scene_name(const std::string& scene_name);

}  // namespace phiq::tools
