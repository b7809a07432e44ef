// Positions and Jacobians of many vertices in double, two vertices per SSE2
// register, with streaming stores for outputs too large for the cache. The
// same bits as the portable loop of vertex_jacobian.h (rotate() and cross()
// lane by lane). x86-64 only (DRB_VERTEX_KERNELS_SSE2); elsewhere
// positionsAndJacobiansSimd declines and the portable loop runs.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "diff_rigid_body/algorithm/free_body/pose.h"
#include "diff_rigid_body/algorithm/detail/cpu_features.h"
#include "diff_rigid_body/types.h"

namespace diff_rigid_body
{
/// Outputs of at least this many bytes are written with non-temporal
/// (streaming) stores in double: they cannot stay in cache anyway, and
/// streaming them skips the read-for-ownership of every output line, which
/// is what keeps the kernel at the speed of a memcpy of its output
/// (bench/, docs/benchmarks.md). Smaller outputs use ordinary stores, so
/// that a consumer that reads them next (e.g. message serialisation) finds
/// them in cache.
constexpr std::size_t kStreamingStoreBytes = std::size_t(16) << 20;

namespace detail
{
#if defined(DRB_VERTEX_KERNELS_SSE2)
/// Loads the coordinates of vertices a and b into lanes (a, b).
inline void loadVertexPair(const double* a, const double* b, __m128d& X, __m128d& Y, __m128d& Z)
{
  if (b == a + 3)  // adjacent: three loads and three shuffles
  {
    const __m128d a01 = _mm_loadu_pd(a), a2b0 = _mm_loadu_pd(a + 2), b12 = _mm_loadu_pd(a + 4);
    X = _mm_shuffle_pd(a01, a2b0, 0x2);
    Y = _mm_shuffle_pd(a01, b12, 0x1);
    Z = _mm_shuffle_pd(a2b0, b12, 0x2);
  }
  else
  {
    X = _mm_loadh_pd(_mm_load_sd(a), b);
    Y = _mm_loadh_pd(_mm_load_sd(a + 1), b + 1);
    Z = _mm_loadh_pd(_mm_load_sd(a + 2), b + 2);
  }
}

/// The pose broadcast to both lanes.
struct Sse2Pose
{
  __m128d r[9];   ///< R(i, j) at 3 i + j
  __m128d tc[9];  ///< T(j, k) at 3 k + j: column k of T
  __m128d t[3];
  explicit Sse2Pose(const BodyPose<double>& pose)
  {
    for (int i = 0; i < 3; ++i)
    {
      for (int j = 0; j < 3; ++j)
      {
        r[3 * i + j] = _mm_set1_pd(pose.R(i, j));
        tc[3 * i + j] = _mm_set1_pd(pose.T(j, i));
      }
      t[i] = _mm_set1_pd(pose.t[i]);
    }
  }
};

/// Stores the 3x6 row-major Jacobian of the low (High = false) or high lane
/// vertex: row i = (C[0][i], C[1][i], C[2][i], e_i), C[c][i] component i of
/// column c.
template <bool High>
inline void storeJacobianLane(const __m128d (&C)[3][3], double* J)
{
  const auto pair = [](__m128d lo, __m128d hi) { return High ? _mm_unpackhi_pd(lo, hi) : _mm_unpacklo_pd(lo, hi); };
  const __m128d ones = _mm_set1_pd(1.0), zeros = _mm_setzero_pd();
  // Columns 4 and 5 of rows 0, 1, 2 in memory order: (0, 0), (1, 0), (0, 1).
  const __m128d tails[3] = { zeros, _mm_set_pd(0.0, 1.0), _mm_set_pd(1.0, 0.0) };
  for (int i = 0; i < 3; ++i)
  {
    _mm_storeu_pd(J + 6 * i, pair(C[0][i], C[1][i]));
    _mm_storeu_pd(J + 6 * i + 2, pair(C[2][i], i == 0 ? ones : zeros));
    _mm_storeu_pd(J + 6 * i + 4, tails[i]);
  }
}

/// Positions (6 values at P, unless P is null) and Jacobians (36 values at
/// J) of body-frame vertices a and b.
inline void positionsAndJacobiansPair(const Sse2Pose& k, const double* a, const double* b, double* P, double* J)
{
  __m128d X, Y, Z;
  loadVertexPair(a, b, X, Y, Z);
  __m128d L[3];
  for (int i = 0; i < 3; ++i)
    L[i] = _mm_add_pd(_mm_add_pd(_mm_mul_pd(k.r[3 * i], X), _mm_mul_pd(k.r[3 * i + 1], Y)),
                      _mm_mul_pd(k.r[3 * i + 2], Z));
  if (P)
  {
    const __m128d px = _mm_add_pd(L[0], k.t[0]), py = _mm_add_pd(L[1], k.t[1]), pz = _mm_add_pd(L[2], k.t[2]);
    _mm_storeu_pd(P, _mm_unpacklo_pd(px, py));          // (ax, ay)
    _mm_storeu_pd(P + 2, _mm_shuffle_pd(pz, px, 0x2));  // (az, bx)
    _mm_storeu_pd(P + 4, _mm_unpackhi_pd(py, pz));      // (by, bz)
  }
  // C[c][i]: component i of column c of J, T_c x L.
  __m128d C[3][3];
  for (int c = 0; c < 3; ++c)
  {
    const __m128d* a_c = k.tc + 3 * c;
    C[c][0] = _mm_sub_pd(_mm_mul_pd(a_c[1], L[2]), _mm_mul_pd(a_c[2], L[1]));
    C[c][1] = _mm_sub_pd(_mm_mul_pd(a_c[2], L[0]), _mm_mul_pd(a_c[0], L[2]));
    C[c][2] = _mm_sub_pd(_mm_mul_pd(a_c[0], L[1]), _mm_mul_pd(a_c[1], L[0]));
  }
  storeJacobianLane<false>(C, J);
  storeJacobianLane<true>(C, J + 18);
}

/// Non-temporal copy of `count` (even) doubles; both pointers 16-byte aligned.
inline void streamCopy(double* out, const double* in, std::size_t count)
{
  for (std::size_t i = 0; i < count; i += 2)
    _mm_stream_pd(out + i, _mm_load_pd(in + i));
}

/// vertexPositionsAndJacobians in double, two vertices per SSE2 register.
/// With Stream (outputs 16-byte aligned), blocks of 16 vertices are computed
/// into an L1 buffer and then streamed out whole-line by whole-line:
/// non-temporal stores interleaved with the arithmetic leave write-combining
/// buffers half full and are slower than ordinary stores.
template <bool Stream>
inline void positionsAndJacobiansSse2(const BodyPose<double>& pose, const Matrix3X<double>& vertices,
                                      const std::vector<std::uint32_t>& indices, double* positions,
                                      double* jacobians)
{
  const bool all = indices.empty();
  const std::size_t count = all ? static_cast<std::size_t>(vertices.cols()) : indices.size();
  const double* base = vertices.data();
  auto vertex = [&](std::size_t n) { return base + 3 * (all ? n : static_cast<std::size_t>(indices[n])); };
  const Sse2Pose k(pose);
  std::size_t n = 0;
  if constexpr (Stream)
  {
    constexpr std::size_t kBlock = 16;
    alignas(64) double J_block[18 * kBlock];
    alignas(64) double P_block[3 * kBlock];
    for (; n + kBlock <= count; n += kBlock)
    {
      for (std::size_t m = 0; m < kBlock; m += 2)
        positionsAndJacobiansPair(k, vertex(n + m), vertex(n + m + 1), positions ? P_block + 3 * m : nullptr,
                                  J_block + 18 * m);
      streamCopy(jacobians + 18 * n, J_block, 18 * kBlock);
      if (positions)
        streamCopy(positions + 3 * n, P_block, 3 * kBlock);
    }
    _mm_sfence();
  }
  for (; n + 2 <= count; n += 2)
    positionsAndJacobiansPair(k, vertex(n), vertex(n + 1), positions ? positions + 3 * n : nullptr,
                              jacobians + 18 * n);
  if (n < count)  // an odd last vertex
    writeVertexOutputs<6>(pose, rotate(pose.R, Eigen::Map<const Vector3<double>>(vertex(n))),
                          positions ? positions + 3 * n : nullptr, jacobians + 18 * n);
}
#endif

/// vertexPositionsAndJacobians in double on the SIMD path: streaming stores
/// for large 16-byte aligned outputs, ordinary ones otherwise. Returns false,
/// having written nothing, when there is no SIMD path (not x86-64) or no
/// Jacobians are asked for (positions alone: the portable loop).
inline bool positionsAndJacobiansSimd(const BodyPose<double>& pose, const Matrix3X<double>& vertices,
                                      const std::vector<std::uint32_t>& indices, double* positions,
                                      double* jacobians)
{
#if defined(DRB_VERTEX_KERNELS_SSE2)
  if (!jacobians)
    return false;
  const std::size_t count = indices.empty() ? static_cast<std::size_t>(vertices.cols()) : indices.size();
  const bool aligned = reinterpret_cast<std::uintptr_t>(jacobians) % 16 == 0 &&
                       reinterpret_cast<std::uintptr_t>(positions) % 16 == 0;  // null is aligned
  if (aligned && 18 * sizeof(double) * count >= kStreamingStoreBytes)
    positionsAndJacobiansSse2<true>(pose, vertices, indices, positions, jacobians);
  else
    positionsAndJacobiansSse2<false>(pose, vertices, indices, positions, jacobians);
  return true;
#else
  (void)pose, (void)vertices, (void)indices, (void)positions, (void)jacobians;
  return false;
#endif
}
}  // namespace detail
}  // namespace diff_rigid_body
