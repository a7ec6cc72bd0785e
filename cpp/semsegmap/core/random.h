// Counter-based random numbers: a value is a pure function of (seed, keys), so that frames are
// byte-identical whatever the thread count or the order in which rays are traced.
#pragma once

#include <cstdint>

namespace semsegmap {

uint64_t hashMix(uint64_t x);
uint64_t hashKeys(uint64_t seed, uint64_t a, uint64_t b = 0, uint64_t c = 0);
// Uniform in [0, 1).
double uniformFromHash(uint64_t h);
// Standard normal from one hash (Box-Muller on two derived uniforms).
double gaussianFromHash(uint64_t h);

// A small sequential generator for procedural generation, where order is fixed anyway.
class SeededRng {
 public:
  explicit SeededRng(uint64_t seed) : state_(hashMix(seed ^ 0x9e3779b97f4a7c15ULL)) {}
  uint64_t next();
  double uniform() { return uniformFromHash(next()); }
  double uniform(double lo, double hi) { return lo + (hi - lo) * uniform(); }
  // Integer in [lo, hi] inclusive.
  int integer(int lo, int hi);
  double gaussian(double sigma) { return sigma * gaussianFromHash(next()); }
  bool chance(double p) { return uniform() < p; }

 private:
  uint64_t state_;
};

}  // namespace semsegmap
