#include "lodforge/core/progress.h"

#include <unistd.h>

#include <csignal>
#include <cstdio>
#include <cstdlib>

#include <fmt/format.h>

#include "lodforge/core/units.h"

namespace lodforge {

namespace {

std::atomic<bool> gCancel{false};
std::atomic<ProgressMode> gMode{ProgressMode::kAuto};

extern "C" void onInterrupt(int signal) {
  if (gCancel.load()) {
    // Second interrupt: the user means it.
    std::signal(signal, SIG_DFL);
    std::raise(signal);
    return;
  }
  gCancel.store(true);
}

std::string formatAmount(std::uint64_t value, Progress::Unit unit) {
  return unit == Progress::Unit::kBytes ? formatBytes(value) : formatCount(value);
}

std::string formatDuration(double seconds) {
  const auto s = static_cast<long>(seconds);
  if (s >= 3600) return fmt::format("{}:{:02}:{:02}", s / 3600, s / 60 % 60, s % 60);
  return fmt::format("{:02}:{:02}", s / 60, s % 60);
}

constexpr std::int64_t kQuietMs = 1000;      // nothing is shown for work shorter than this
constexpr std::int64_t kBarEveryMs = 200;    // terminal redraw interval
constexpr std::int64_t kLineEveryMs = 5000;  // plain-line interval (logs, CI)

}  // namespace

void installInterruptHandler() {
  std::signal(SIGINT, onInterrupt);
  std::signal(SIGTERM, onInterrupt);
}
void requestCancel() {
  gCancel.store(true);
}
void clearCancel() {
  gCancel.store(false);
}
bool cancelRequested() {
  return gCancel.load(std::memory_order_relaxed);
}
Status checkCancelled() {
  if (!cancelRequested()) return {};
  return Error{ErrorKind::kCancelled, "cancelled"};
}
void checkpointReached(std::string_view kind) {
  struct Interrupt {
    std::string kind;
    long after = 0;
    bool kill = false;
  };
  static const Interrupt interrupt = [] {
    const char* value = std::getenv("LODFORGE_INTERRUPT_AFTER");
    const std::string_view spec = value ? value : "";
    const std::size_t colon = spec.find(':');
    if (colon == std::string_view::npos) return Interrupt{};
    const std::string count(spec.substr(colon + 1));
    char* end = nullptr;
    const long after = std::strtol(count.c_str(), &end, 10);
    return Interrupt{std::string(spec.substr(0, colon)), after, std::string_view(end) == ":kill"};
  }();
  static std::atomic<long> reached{0};
  if (interrupt.after > 0 && kind == interrupt.kind &&
      reached.fetch_add(1) + 1 == interrupt.after) {
    if (interrupt.kill) ::raise(SIGKILL);  // a process that dies, not one that stops
    requestCancel();
  }
}

void setProgressMode(ProgressMode mode) {
  gMode.store(mode);
}

Progress::Progress(std::string label, std::uint64_t total, Unit unit)
    : label_(std::move(label)),
      total_(total),
      unit_(unit),
      mode_(label_.empty() ? ProgressMode::kOff : gMode.load()),
      start_(std::chrono::steady_clock::now()) {
  if (mode_ == ProgressMode::kAuto) mode_ = ::isatty(2) ? ProgressMode::kBar : ProgressMode::kLines;
  nextDrawMs_ = kQuietMs;
}

Progress::~Progress() {
  finish();
}

void Progress::advance(std::uint64_t amount) {
  done_.fetch_add(amount, std::memory_order_relaxed);
  if (mode_ == ProgressMode::kOff) return;
  const auto elapsedMs = std::chrono::duration_cast<std::chrono::milliseconds>(
                             std::chrono::steady_clock::now() - start_)
                             .count();
  if (elapsedMs < nextDrawMs_.load(std::memory_order_relaxed)) return;
  std::unique_lock lock(drawMutex_, std::try_to_lock);
  if (!lock || finished_) return;
  nextDrawMs_ = elapsedMs + (mode_ == ProgressMode::kBar ? kBarEveryMs : kLineEveryMs);
  draw(false);
}

void Progress::finish() {
  std::lock_guard lock(drawMutex_);
  if (finished_) return;
  finished_ = true;
  if (drawn_) draw(true);  // only close what was shown; quick work stays silent
}

void Progress::draw(bool final) {
  const std::uint64_t done = std::min(done_.load(), total_);
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  const double fraction = total_ ? static_cast<double>(done) / static_cast<double>(total_) : 1.0;
  std::string eta;
  if (!final && fraction > 0.01) eta = " eta " + formatDuration(seconds / fraction - seconds);
  const std::string amounts =
      fmt::format("{}/{}", formatAmount(done, unit_), formatAmount(total_, unit_));
  if (mode_ == ProgressMode::kBar) {
    constexpr int kWidth = 30;
    const int filled = static_cast<int>(fraction * kWidth);
    fmt::print(stderr, "\r{} [{:=<{}}{: <{}}] {:3.0f}% {} {}{}\033[K{}", label_, "", filled, "",
               kWidth - filled, fraction * 100, amounts, formatDuration(seconds), eta,
               final ? "\n" : "");
  } else {
    fmt::print(stderr, "{}: {:.0f}% ({}) {}{}\n", label_, fraction * 100, amounts,
               formatDuration(seconds), final ? " done" : eta);
  }
  std::fflush(stderr);
  drawn_ = true;
}

}  // namespace lodforge
