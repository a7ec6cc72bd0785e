#include "semsegmap/core/random.h"

#include <cmath>

namespace semsegmap {

uint64_t hashMix(uint64_t x) {
  // splitmix64 finaliser: full avalanche, cheap.
  x += 0x9e3779b97f4a7c15ULL;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ULL;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebULL;
  return x ^ (x >> 31);
}

uint64_t hashKeys(uint64_t seed, uint64_t a, uint64_t b, uint64_t c) {
  return hashMix(hashMix(hashMix(hashMix(seed) ^ a) ^ b) ^ c);
}

double uniformFromHash(uint64_t h) {
  return static_cast<double>(h >> 11) * 0x1.0p-53;
}

double gaussianFromHash(uint64_t h) {
  const double u1 = (static_cast<double>(h >> 40) + 0.5) * 0x1.0p-24;
  const double u2 = static_cast<double>(hashMix(h) >> 11) * 0x1.0p-53;
  return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * M_PI * u2);
}

uint64_t SeededRng::next() {
  state_ += 0x9e3779b97f4a7c15ULL;
  return hashMix(state_);
}

int SeededRng::integer(int lo, int hi) {
  return lo + static_cast<int>(uniform() * (hi - lo + 1));
}

}  // namespace semsegmap
