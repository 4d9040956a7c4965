// Deterministic random numbers for generators and property tests. The same seed gives the same
// stream on every machine and standard library (std::uniform_*_distribution does not).
#pragma once

#include <cmath>
#include <cstdint>

namespace lodforge {

// SplitMix64: tiny state, good statistical quality, cheap to derive independent streams.
class Random {
 public:
  explicit Random(std::uint64_t seed) : state_(seed) {}
  // An independent stream for item `index` (an object, a batch) of the stream seeded by `seed`,
  // so parallel work is reproducible whatever the thread count.
  static Random forItem(std::uint64_t seed, std::uint64_t index) {
    Random mixer(seed ^ (index * 0xD1B54A32D192ED03ull));
    return Random(mixer.next());
  }

  std::uint64_t next() {
    std::uint64_t z = (state_ += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
  }
  // Uniform in [0, 1).
  double uniform() { return static_cast<double>(next() >> 11) * 0x1.0p-53; }
  double uniform(double lo, double hi) { return lo + (hi - lo) * uniform(); }
  // Uniform integer in [0, n).
  std::uint64_t below(std::uint64_t n) { return n ? next() % n : 0; }
  // Log-uniform in [lo, hi]: sizes spread over orders of magnitude.
  double logUniform(double lo, double hi) { return lo * std::exp(std::log(hi / lo) * uniform()); }

 private:
  std::uint64_t state_;
};

}  // namespace lodforge
