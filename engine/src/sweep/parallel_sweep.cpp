// A parallel sweep's chunks (chunked_sweep.hpp): a chunk's rows from its seed with its seam step, streamed to the
// caller or held (encoded by the thread that computes them when a RowWriter takes the rows), the seam check that
// accepts a chunk as the sequential sweep's continuation, and the delivery of a held chunk in order on the caller's
// thread. The schedule that seeds and runs them is in chunk_schedule.cpp.
#include "sweep/parallel_sweep.hpp"
#include "phiq/text.hpp"

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "sweep/chunked_sweep.hpp"
#include "sweep/streamed_rows.hpp"

namespace phiq::detail {

namespace {

// Two solutions of the same position problem are the same one if they differ by less than `limit` tolerances in
// every coordinate (each is within about one of the exact root, or of its rounding level; another branch is a
// finite distance away).
bool same_solution(const Model& model, const Eigen::VectorXd& a, const double* b, double tol, double limit) {
  return detail::scaled_distance(model, a.data(), b, a.data(), tol) <= limit;
}

// Why a parallel chunk's first row q0 (null: it did not converge, `failure` saying why) is not where the sweep in
// order arrives, seam_q (null: unknown), beyond `limit` tolerances: the parallel_fallback warning's cause. `signs`:
// the model's bodies with Euler parameters (the sweep's own, made once). Another branch is told at the coordinate
// farthest from the seam in units of the tolerance test, in its own unit (metres, radians), with how closely two
// rows of one branch agree there: "6.2e-5 tolerances" told no one how far the chunk was off.
std::string rejection_cause(const Model& model, const EulerSeedSigns& signs, const std::string& failure,
                            const Eigen::VectorXd* seam_q, const double* q0, double tol, double limit) {
  if (!q0) return "its first row did not converge from its seed (" + failure + ")";
  if (!seam_q) return "the chunk before it did not reach the chunk's first time point (its seam step failed)";
  Eigen::VectorXd turned = Eigen::Map<const Eigen::VectorXd>(q0, seam_q->size());
  if (signs.turn_like(seam_q->data(), turned) && same_solution(model, *seam_q, turned.data(), tol, limit))
    return "its first row has the other sign of a body's Euler parameters (e and −e: one orientation) than the "
           "sweep in order";
  const double* cs = model.tolerance_scales().coordinate_scale.data();
  Index worst = 0;
  double worst_ratio = -1.0, worst_allowed = 0.0;
  for (Index j = 0; j < seam_q->size(); ++j) {
    const double allowed = tol * cs[j] + detail::kUlpFloor * std::fabs((*seam_q)(j));
    const double r = std::fabs((*seam_q)(j)-q0[j]) / allowed;
    if (!(r <= worst_ratio)) worst = j, worst_ratio = r, worst_allowed = allowed;  // (a NaN is the worst)
  }
  const char* symbol = unit_symbol(model.coordinate_unit(worst));
  const std::string unit = *symbol ? std::string(" ") + symbol : std::string();
  return "its first row is another branch: '" + model.coordinate_names()[static_cast<std::size_t>(worst)] + "' is " +
         significant(std::fabs((*seam_q)(worst)-q0[worst]), 3) + unit +
         " from where the sweep in order arrives, where two rows of one branch agree to ±" +
         significant(limit * worst_allowed, 2) + unit;
}

}  // namespace

// Two solutions of the same problem agree to 100 tolerances, or, where Newton stopped at the rounding level (a long
// chain), to 10× how well that stop says q is known: another branch is a finite distance away.
double ChunkedSweep::seam_limit(const Chunk& ch) const {
  return std::max(100.0, 10.0 * std::max(at_.seam_rounding, ch.first_rounding));
}

// Whether a chunk whose first row is at q0 continues the sweep in order: chunk 0 does by construction; another
// must start where the sweep, continued in order from the last delivered row, arrives (the previous chunk's seam).
bool ChunkedSweep::continues(const Chunk& ch, const double* q0) const {
  return ch.k0 == 1 || (at_.seam_known && same_solution(model_, at_.seam_q, q0, opt_.newton.tolerance, seam_limit(ch)));
}

// A chunk whose first row is q0 (null: it has none) does not continue the sweep: why, for the fallback warning.
void ChunkedSweep::not_continued(const Chunk& ch, const double* q0) {
  fallback_cause_ = rejection_cause(model_, euler_signs_, ch.sum.message, at_.seam_known ? &at_.seam_q : nullptr, q0,
                                    opt_.newton.tolerance, seam_limit(ch));
}

// A chunk delivered (its first `good` rows): the state an ordered continuation starts from, its seam, and its
// summary, up to its last good row. Returns kDelivered when every row was good, kFailedAfterSome when it failed
// after them (the rest then runs in order from its last good row, where the failure is found and reported as a
// sequential sweep's).
int ChunkedSweep::accept(Chunk& ch, Eigen::VectorXd& q, Eigen::VectorXd& qd, Eigen::VectorXd& qdd) {
  SweepSummary& sum = run_.sum;
  at_.q.swap(q);
  if (need_v_) at_.qd.swap(qd);
  if (need_a_) at_.qdd.swap(qdd);
  at_.resume = ch.k0 + ch.good;
  at_.seam_known = ch.ok && ch.has_seam;
  if (at_.seam_known) at_.seam_q.swap(ch.seam_q), at_.seam_rounding = ch.rounding;
  sum.subdivisions += ch.sum.subdivisions;
  sum.singular_positions += ch.sum.singular_positions;
  sum.warnings.insert(sum.warnings.end(), ch.sum.warnings.begin(), ch.sum.warnings.end());
  if (ch.sum.min_rcond > 0.0 && (sum.min_rcond == 0.0 || ch.sum.min_rcond < sum.min_rcond))
    sum.min_rcond = ch.sum.min_rcond, sum.min_rcond_time = ch.sum.min_rcond_time;
  ++sum.parallel_chunks;
  return ch.ok ? kDelivered : kFailedAfterSome;
}

// The caller stopped the sweep at this row: its workspace ends there.
void ChunkedSweep::stopped_at(const Eigen::VectorXd& q, const Eigen::VectorXd& qd, const Eigen::VectorXd& qdd) {
  at_.q = q;
  if (need_v_) at_.qd = qd;
  if (need_a_) at_.qdd = qdd;
}

// A chunk being computed: its sweeper and workspace, and how far it got.
struct ChunkedSweep::ChunkRun {
  Chunk& ch;
  Sweeper& s;
  Workspace& w;
  bool stream;
  int outcome = kDelivered;
  // The summary up to the last good row: what is delivered of it (sub-steps, warnings and the condition of a
  // failed step or of the seam step belong to the sweep that runs them next).
  SweepSummary good_sum;
};

// The chunk's row just converged, kept: delivered at once when streamed, else held (hold_row). False: stop the
// chunk (streaming: rejected or stopped by the caller).
bool ChunkedSweep::keep_row(ChunkRun& cr) {
  Chunk& ch = cr.ch;
  Sweeper& s = cr.s;
  const State& st = s.state();
  const Index k = ch.k0 + ch.good;
  // outputs that fail (efforts that overflow) end the chunk as a failed step does: the rest runs in order from its
  // last good row, which fails there and says why
  if (!s.row_outputs(k)) return ch.ok = false;
  if (ch.good == 0) ch.first_rounding = std::max(s.take_rounding_level(), ch.first_rounding);
  cr.good_sum.warnings = ch.sum.warnings, cr.good_sum.subdivisions = ch.sum.subdivisions;
  cr.good_sum.singular_positions = ch.sum.singular_positions;
  cr.good_sum.min_rcond = ch.sum.min_rcond, cr.good_sum.min_rcond_time = ch.sum.min_rcond_time;
  if (!cr.stream) {
    hold_row(cr);
    return true;
  }
  if (ch.good == 0 && !continues(ch, st.q.data())) return not_continued(ch, st.q.data()), cr.outcome = kRejected, false;
  ++ch.good;
  if (!run_.deliver(k, st.q, st.qd, st.qdd, s.motions(), cr.w.phi, s.rcond(), s.det_sign(), s.det_sign_time(),
                    s.row_quality())) {
    stopped_at(st.q, st.qd, st.qdd);
    return cr.outcome = kStopped, false;
  }
  return true;
}

// A held chunk's row: what its delivery reads (the bifurcation check and the summary's accuracy read every row's
// sign and quality), and either its encoding (Run::chunks_encode) or its vectors and outputs.
void ChunkedSweep::hold_row(ChunkRun& cr) {
  Chunk& ch = cr.ch;
  Sweeper& s = cr.s;
  const State& st = s.state();
  const Index k = ch.k0 + ch.good;
  Row& r = ch.rows[static_cast<std::size_t>(ch.good)];
  r.det_sign = s.det_sign(), r.det_sign_t = s.det_sign_time();
  r.quality = s.row_quality();
  const RowMotions rm = s.motions();
  if (encode_) {
    if (opt_.writes_row(k, run_.time_of(k))) {
      // (no joint angles to unwrap: Run::chunks_encode; a distance is delivered as measured)
      run_.writer->encode(run_.view_of(k, st.q, st.qd, st.qdd, rm, cr.w.phi, s.rcond(), rm.joints), ch.encoded);
      ++ch.encoded_rows, ch.last_encoded = k;
    }
  } else if (rm.joints) {
    r.joints.assign(rm.joints, rm.joints + opt_.joints.size());
  }
  if (!layout_.keeps_vectors(ch.rows.size(), static_cast<std::size_t>(ch.good++))) return;
  stream_copy(st.q, r.q);
  if (need_v_) stream_copy(st.qd, r.qd);
  if (need_a_) stream_copy(st.qdd, r.qdd);
  if (encode_) return;  // (the vectors of its ends only, for the seam check and an ordered continuation)
  if (opt_.residuals) r.phi = cr.w.phi;
  r.rcond = s.rcond();
  if (!opt_.points.empty()) r.points.assign(s.point_motions(), s.point_motions() + opt_.points.size());
  if (rm.orientations) r.orientations.assign(rm.orientations, rm.orientations + opt_.orientations.size());
  if (rm.sensitivities)
    r.sensitivities.assign(rm.sensitivities, rm.sensitivities + SensitivityLayout{model_.num_coordinates()}.size(
                                                                    opt_.sensitivities.size()));
  if (rm.efforts) r.efforts.assign(rm.efforts, rm.efforts + effort_values(opt_.efforts, opt_.sensitivities.size()));
}

// Chunk c: its rows from its seed (chunk 0: in order from row 0), then the seam step. `stream`: the caller's
// thread runs the chunk next to be delivered, and delivers each row as it is computed instead of holding it
// (one thread always does): the same rows, the same checks, no buffers. Returns, when streaming, what
// deliver_chunk returns.
int ChunkedSweep::run_chunk(Index c, Chunk& ch, bool stream) {
  Workspace* held = pool_.acquire();
  Workspace& w = *held;
  const WorkCounters w0 = w.counters;
  ch.k0 = first_row(c), ch.k1 = last_row(c);
  Sweeper s(model_, opt_, w, ch.sum, &row0_sweeper_);
  if (!stream) {
    ch.rows.resize(static_cast<std::size_t>(ch.k1 - ch.k0 + 1));
    const double text_bytes = layout_.encoded_row_bytes * static_cast<double>(ch.rows.size());
    buffers_.take(ch.rows, ch.encoded, static_cast<std::size_t>(text_bytes));
  }
  ChunkRun cr{ch, s, w, stream, kDelivered, {}};
  if (c > 0) ch.first_rounding = seeds_.rounding[static_cast<std::size_t>(c)];
  if (c == 0) {  // continues row 0 in order: the sequential sweep itself
    w.q = at_.q, w.qd = at_.qd, w.qdd = at_.qdd;
    s.adopt(run_.time_of(0));
    s.take_branch_tangent(row0_sweeper_);
    ch.ok = s.advance(run_.time_of(ch.k0), 0);
  } else {
    ch.ok = s.start_from(run_.time_of(ch.k0), seeds_.q[static_cast<std::size_t>(c)],
                         seeds_.error[static_cast<std::size_t>(c)]);
  }
  bool going = ch.ok && keep_row(cr);
  for (Index k = ch.k0 + 1; going && k <= ch.k1; ++k) going = (ch.ok = s.advance(run_.time_of(k), 0)) && keep_row(cr);
  // The last good row's state, where an ordered continuation starts (before the seam step moves the stepper on):
  // a streamed chunk holds no rows, and a held one that failed kept only its ends' vectors.
  if ((stream || !ch.ok) && ch.good > 0) ch.end = s.state();
  if (going && ch.k1 < opt_.steps && s.advance_position(run_.time_of(ch.k1 + 1))) {
    ch.has_seam = true;  // the seam row belongs to the next chunk
    ch.seam_q = s.state().q;
  }
  ch.rounding = std::max(s.take_rounding_level(), ch.first_rounding);
  ch.sum.warnings.swap(cr.good_sum.warnings);
  ch.sum.subdivisions = cr.good_sum.subdivisions, ch.sum.singular_positions = cr.good_sum.singular_positions;
  ch.sum.min_rcond = cr.good_sum.min_rcond, ch.sum.min_rcond_time = cr.good_sum.min_rcond_time;
  add_counters(ch.sum.counters, w.counters, w0);
  if (stream && cr.outcome == kDelivered) {
    if (ch.good == 0) {
      cr.outcome = kRejected;  // no first row: rejected, the rest runs in order
      not_continued(ch, nullptr);
    } else {
      add_counters(others_, ch.sum.counters, WorkCounters{});
      cr.outcome = accept(ch, ch.end.q, ch.end.qd, ch.end.qdd);
    }
  }
  pool_.release(held);
  if (!stream) stream_fence();  // the chunk's streamed rows are complete before it is marked done for the caller
  return cr.outcome;
}

// Accepts and delivers a chunk computed ahead: its rows one by one, or, encoded, counted one by one and written
// at once. Returns what a streamed chunk's run_chunk returns (Outcome).
int ChunkedSweep::deliver_chunk(Chunk& ch) {
  if (ch.good == 0 || !continues(ch, ch.rows[0].q.data()))
    return not_continued(ch, ch.good == 0 ? nullptr : ch.rows[0].q.data()), kRejected;
  const Row& last = ch.rows[static_cast<std::size_t>(ch.good - 1)];  // (its vectors: when ok, or in ch.end)
  const State* failed_end = ch.ok ? nullptr : &ch.end;
  if (encode_) {
    for (Index k = ch.k0; k < ch.k0 + ch.good; ++k) {
      const Row& r = ch.rows[static_cast<std::size_t>(k - ch.k0)];
      run_.count_row(run_.time_of(k), r.det_sign, r.det_sign_t, r.quality);
    }
    if (!run_.write_encoded(ch.encoded, ch.encoded_rows, ch.last_encoded)) {
      if (failed_end)
        stopped_at(failed_end->q, failed_end->qd, failed_end->qdd);
      else
        stopped_at(last.q, last.qd, last.qdd);
      return kStopped;
    }
  } else {
    for (Index k = ch.k0; k < ch.k0 + ch.good; ++k) {
      const Row& r = ch.rows[static_cast<std::size_t>(k - ch.k0)];
      if (!run_.deliver(k, r.q, r.qd, r.qdd, r.motions(), r.phi, r.rcond, r.det_sign, r.det_sign_t, r.quality)) {
        stopped_at(r.q, r.qd, r.qdd);
        return kStopped;
      }
    }
  }
  add_counters(others_, ch.sum.counters, WorkCounters{});
  // the state an ordered continuation starts from: the chunk's last good row (freed once delivered)
  if (!ch.ok) return accept(ch, ch.end.q, ch.end.qd, ch.end.qdd);
  Row& end = ch.rows.back();
  return accept(ch, end.q, end.qd, end.qdd);
}

}  // namespace phiq::detail
