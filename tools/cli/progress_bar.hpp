// A progress bar for long sweeps on a terminal: `phiq run` draws it on standard error when that is a tty (never in
// files or pipes, where '\r' redraws would be garbage), from the thread that delivers the rows.
#pragma once

#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <string>

namespace phiq::tools {

class ProgressBar {
 public:
  enum class Mode { kAuto, kAlways, kNever };
  // `rows`: the rows the sweep delivers. kAuto shows the bar only when stderr is a terminal, and only once the
  // sweep has run for kDelay (short sweeps stay silent); kAlways draws from the first row (for tests and logs).
  ProgressBar(long long rows, Mode mode) : rows_(rows > 0 ? rows : 1), start_(Clock::now()) {
    enabled_ = mode == Mode::kAlways || (mode == Mode::kAuto && ::isatty(STDERR_FILENO));
    delay_ = mode == Mode::kAlways ? Clock::duration::zero() : kDelay;
    next_ = start_ + delay_;
  }
  ~ProgressBar() { finish(); }
  ProgressBar(const ProgressBar&) = delete;
  ProgressBar& operator=(const ProgressBar&) = delete;

  // Row `done` (1-based count) has been delivered. Costs one clock read when nothing is drawn; draws at most
  // 1 / kPeriod times a second.
  void update(long long done) {
    if (!enabled_) return;
    const Clock::time_point now = Clock::now();
    if (now < next_ && done < rows_) return;
    next_ = now + kPeriod;
    draw(done, now);
  }
  // Erases the bar (the summary line follows on a clean line).
  void finish() {
    if (!drawn_) return;
    std::fputs("\r\033[K", stderr);
    std::fflush(stderr);
    drawn_ = false;
  }

 private:
  using Clock = std::chrono::steady_clock;
  static constexpr Clock::duration kPeriod = std::chrono::milliseconds(100);
  static constexpr Clock::duration kDelay = std::chrono::milliseconds(300);

  void draw(long long done, Clock::time_point now) {
    constexpr int kWidth = 30;
    const double f = static_cast<double>(done) / static_cast<double>(rows_);
    const int full = static_cast<int>(f * kWidth);
    const double elapsed = std::chrono::duration<double>(now - start_).count();
    std::string bar(static_cast<std::size_t>(full), '#');
    bar.resize(kWidth, '.');
    char eta[32] = "";
    if (done > 0 && done < rows_) std::snprintf(eta, sizeof eta, ", %.0f s left", elapsed * (1.0 / f - 1.0));
    std::fprintf(stderr, "\rphiq: [%s] %3d%% %lld/%lld rows, %.1f s%s\033[K", bar.c_str(), static_cast<int>(100.0 * f),
                 done, rows_, elapsed, eta);
    std::fflush(stderr);
    drawn_ = true;
  }

  long long rows_;
  bool enabled_ = false, drawn_ = false;
  Clock::time_point start_, next_;
  Clock::duration delay_;
};

}  // namespace phiq::tools
