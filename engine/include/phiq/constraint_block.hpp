// Constraint blocks: all constraints of one kind, evaluated in one loop (one virtual call per block and operation,
// not per constraint). The solver sees only ConstraintBlock.
#pragma once

#include <algorithm>
#include <memory>
#include <vector>

#include "phiq/constraint_kinds.hpp"

namespace phiq {

class ConstraintBlock {
 public:
  virtual ~ConstraintBlock() = default;
  virtual const char* kind() const = 0;
  virtual std::size_t size() const = 0;
  virtual int rows_per_constraint() const = 0;
  virtual Index first_row(std::size_t i) const = 0;

  // Each writes the rows of constraints [begin, end) at their global row offsets.
  virtual void residual(std::size_t begin, std::size_t end, const double* q, double t, double* phi) const = 0;
  // Accumulates Φq values into the CSC value array through slot_of_entry (one slot per emitted entry).
  virtual void jacobian(std::size_t begin, std::size_t end, const double* q, double t, const Index* slot_of_entry,
                        double* csc_values) const = 0;
  // Φt of the time-dependent constraints only (the others' rows are left untouched: they are zero).
  virtual void phi_t(std::size_t begin, std::size_t end, const double* q, double t, double* out) const = 0;
  virtual void gamma(std::size_t begin, std::size_t end, const double* q, const double* qd, double t,
                     double* out) const = 0;
  virtual bool depends_on_time(std::size_t i) const = 0;

  // Used once, while the model is built:
  // appends the (row, column) of every Jacobian entry and records where each constraint's entries start;
  virtual void build_pattern(std::vector<Index>& rows, std::vector<Index>& cols) = 0;
  // marks the unit of every coordinate the constraints read (kNone where they do not tell);
  virtual void infer_coordinate_units(std::vector<Unit>& units) const = 0;
  // writes the unit of every row, given the coordinates' units;
  virtual void row_units(const std::vector<Unit>& coordinate_units, std::vector<Unit>& units) const = 0;
  // the largest length the constraints carry as data (link lengths, attachment arms), 0 if none.
  virtual double characteristic_length() const = 0;
};

namespace detail {
// Pattern mode: records the column of every entry that falls on a coordinate.
struct PatternSink {
  Index row0;
  std::vector<Index>* rows;
  std::vector<Index>* cols;
  void operator()(int row, const Slot& s, double) {
    if (s.is_coordinate()) rows->push_back(row0 + row), cols->push_back(s.coord);
  }
};
// Value mode: same entries, same order, values accumulated into their CSC slots.
struct ValueSink {
  const Index* slot;
  double* values;
  void operator()(int, const Slot& s, double v) {
    if (s.is_coordinate()) values[*slot++] += v;
  }
};
}  // namespace detail

template <class Spec>
Index max_coordinate(const Spec& spec) {
  Index m = -1;
  spec.for_each_slot([&](const Slot& s, Unit) { m = std::max(m, s.coord); });
  return m;
}

template <class Spec>
class TypedBlock final : public ConstraintBlock {
 public:
  struct Entry {
    Spec spec;
    Index row0;  // first global row
    Index nz0;   // first entry in the model's triplet list
  };

  const char* kind() const override { return Spec::kKind; }
  std::size_t size() const override { return entries_.size(); }
  int rows_per_constraint() const override { return Spec::kRows; }
  Index first_row(std::size_t i) const override { return entries_[i].row0; }
  const Spec& spec(std::size_t i) const { return entries_[i].spec; }
  std::vector<Entry>& entries() { return entries_; }

  void residual(std::size_t begin, std::size_t end, const double* q, double t, double* phi) const override {
    for (std::size_t i = begin; i < end; ++i) entries_[i].spec.residual(q, t, phi + entries_[i].row0);
  }
  void jacobian(std::size_t begin, std::size_t end, const double* q, double t, const Index* slot_of_entry,
                double* csc_values) const override {
    for (std::size_t i = begin; i < end; ++i) {
      detail::ValueSink sink{slot_of_entry + entries_[i].nz0, csc_values};
      entries_[i].spec.jacobian(q, t, sink);
    }
  }
  void phi_t(std::size_t begin, std::size_t end, const double* q, double t, double* out) const override {
    for (std::size_t i = begin; i < end; ++i)
      if (entries_[i].spec.depends_on_time()) entries_[i].spec.phi_t(q, t, out + entries_[i].row0);
  }
  void gamma(std::size_t begin, std::size_t end, const double* q, const double* qd, double t,
             double* out) const override {
    for (std::size_t i = begin; i < end; ++i) entries_[i].spec.gamma(q, qd, t, out + entries_[i].row0);
  }
  bool depends_on_time(std::size_t i) const override { return entries_[i].spec.depends_on_time(); }

  void build_pattern(std::vector<Index>& rows, std::vector<Index>& cols) override {
    for (Entry& e : entries_) {
      e.nz0 = static_cast<Index>(rows.size());
      detail::PatternSink sink{e.row0, &rows, &cols};
      std::vector<double> zeros(static_cast<std::size_t>(max_coordinate(e.spec) + 1), 0.0);
      // values are ignored in pattern mode; evaluate at a harmless point (entries never depend on values)
      e.spec.jacobian(zeros.data(), 0.0, sink);
    }
  }
  void infer_coordinate_units(std::vector<Unit>& units) const override {
    for (const Entry& e : entries_)
      e.spec.for_each_slot([&](const Slot& s, Unit u) {
        if (!s.is_coordinate() || u == Unit::kNone) return;
        Unit& cu = units[static_cast<std::size_t>(s.coord)];
        if (cu == Unit::kNone) cu = u;
        else if (cu != u) cu = Unit::kNone;  // used as both: fall back to the plain tolerance
      });
  }
  void row_units(const std::vector<Unit>& coordinate_units, std::vector<Unit>& units) const override {
    for (const Entry& e : entries_)
      for (int r = 0; r < Spec::kRows; ++r)
        units[static_cast<std::size_t>(e.row0 + r)] = e.spec.row_unit(r, coordinate_units);
  }
  double characteristic_length() const override {
    double l = 0.0;
    for (const Entry& e : entries_) l = std::max(l, e.spec.characteristic_length());
    return l;
  }

 private:
  std::vector<Entry> entries_;
};

}  // namespace phiq
