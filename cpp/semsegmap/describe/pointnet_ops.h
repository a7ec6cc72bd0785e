// The two sampling operations of PointNet++ set abstraction, farthest point sampling and ball
// query, written for the CPU on plain interleaved xyz arrays (the original ships them as CUDA
// kernels). Both are deterministic: the result depends only on the coordinates and their order.
#pragma once

#include <vector>

namespace semsegmap {

// `m` indices into the `n` points of `xyz` (x y z interleaved): `start` first, then each time
// the point farthest (squared Euclidean) from those already chosen; ties go to the lowest index.
// Requires 0 < m <= n. `out` holds m indices; `scratch` is resized to n.
void farthestPointSample(const float* xyz, int n, int m, int start, int* out,
                         std::vector<float>& scratch);
std::vector<int> farthestPointSample(const float* xyz, int n, int m, int start = 0);

// For each of the `m` centres (x y z interleaved), the first `k` indices, in index order, of the
// points with squared distance < radius^2; when fewer than k are found the list is padded with
// the first one found (as in PointNet++), and a centre with no point in the ball gets its
// nearest point. `out` holds m * k indices, row-major by centre.
void ballQuery(const float* xyz, int n, const float* centres, int m, float radius, int k, int* out);
std::vector<int> ballQuery(const float* xyz, int n, const float* centres, int m, float radius,
                           int k);

}  // namespace semsegmap
