// Vertex positions, vertex Jacobians and their vector-Jacobian product.
//
//   p = R(r) p0 + t                     p0: vertex in the body frame (origin at COM) [m]
//   J = dp/dq = [ -[R p0]_x T | I3 ]    3x6, columns in q order
//
// Column k < 3 of J is T_k x (R p0): the world axis of the k-th Euler
// rotation crossed with the lever arm, so trigonometry is done once per body
// and each vertex costs one 3x3 product and three cross products.
//
// Backprop (vector-Jacobian product), given g_i = dL/dp_i:
//   dL/dr = T^T sum_i (R p0_i) x g_i,   dL/dt = sum_i g_i.
// With W = sum_i g_i p0_i^T (3x3) and X = R W^T = sum_i (R p0_i) g_i^T,
//   sum_i (R p0_i) x g_i = (X12 - X21, X20 - X02, X01 - X10),
// so the per-vertex work is one 3x3 rank-1 update; J is never formed.
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <type_traits>
#include <vector>

// x86-64 always has SSE2: the double kernels below use it for streaming
// stores and two-vertex lanes; other targets take the portable loops.
#if defined(__SSE2__) && defined(__x86_64__)
#define DRB_VERTEX_KERNELS_SSE2 1
#include <emmintrin.h>
// AVX2 + FMA for the backprop sum, compiled per function (target
// attribute) and chosen at run time from CPUID: the package's flags stay at
// the x86-64 baseline (no -march), the binary runs on any x86-64.
#if defined(__GNUC__)
#define DRB_VERTEX_KERNELS_AVX2 1
#include <immintrin.h>
#endif
#endif

#include "diff_rigid_body/rpy.h"

namespace diff_rigid_body
{
template <typename Scalar>
using Matrix3X = Eigen::Matrix<Scalar, 3, Eigen::Dynamic>;

/// Everything a vertex kernel needs from q, computed once per body.
template <typename Scalar>
struct BodyPose
{
  Matrix3<Scalar> R;  ///< body axes -> fixed frame
  Matrix3<Scalar> T;  ///< Euler rates -> world angular velocity
  Vector3<Scalar> t;  ///< COM in the fixed frame [m]

  template <typename Derived>
  explicit BodyPose(const Eigen::MatrixBase<Derived>& q)
  {
    const RpyTrig<Scalar> trig(q[PHI], q[THETA], q[PSI]);
    R = rpyToMatrix(trig);
    T = angularVelocityMatrixWorld(trig);
    t << q[TX], q[TY], q[TZ];
  }
};

namespace detail
{
/// R p0 with a fixed order of operations, (R_i0 x + R_i1 y) + R_i2 z per
/// row, shared by every vertex kernel (scalar and SIMD paths), so that all
/// of them return the same bits for the same vertex.
template <typename Scalar, typename Derived>
Vector3<Scalar> rotate(const Matrix3<Scalar>& R, const Eigen::MatrixBase<Derived>& p0)
{
  const Scalar x = p0[0], y = p0[1], z = p0[2];
  return Vector3<Scalar>((R(0, 0) * x + R(0, 1) * y) + R(0, 2) * z,  //
                         (R(1, 0) * x + R(1, 1) * y) + R(1, 2) * z,  //
                         (R(2, 0) * x + R(2, 1) * y) + R(2, 2) * z);
}

/// a x b, component by component as written (the SIMD paths repeat it).
template <typename Scalar, typename DerivedA>
Vector3<Scalar> cross(const Eigen::MatrixBase<DerivedA>& a, const Vector3<Scalar>& b)
{
  return Vector3<Scalar>(a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]);
}
}  // namespace detail

/// p = R p0 + t.
template <typename Scalar>
Vector3<Scalar> vertexPosition(const BodyPose<Scalar>& pose, const Vector3<Scalar>& p0)
{
  return detail::rotate(pose.R, p0) + pose.t;
}

/// J = dp/dq (3x6) for one body-frame vertex p0.
template <typename Scalar>
Matrix36<Scalar> vertexJacobian(const BodyPose<Scalar>& pose, const Vector3<Scalar>& p0)
{
  const Vector3<Scalar> lever = detail::rotate(pose.R, p0);
  Matrix36<Scalar> J;
  for (int k = 0; k < 3; ++k)
    J.col(k) = detail::cross(pose.T.col(k), lever);
  J.template rightCols<3>().setIdentity();
  return J;
}

/// Outputs of at least this many bytes are written with non-temporal
/// (streaming) stores in double: they cannot stay in cache anyway, and
/// streaming them skips the read-for-ownership of every output line, which
/// is what keeps the kernel at the speed of a memcpy of its output
/// (bench/, docs/benchmarks.md). Smaller outputs use ordinary stores, so
/// that a consumer that reads them next (e.g. message serialisation) finds
/// them in cache.
constexpr std::size_t kStreamingStoreBytes = std::size_t(16) << 20;

#if defined(DRB_VERTEX_KERNELS_SSE2)
namespace detail
{
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

/// Positions (6 values at P, unless P is null) and Jacobians (36 values at
/// J) of body-frame vertices a and b: rotate() and cross() lane by lane.
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
  const __m128d ones = _mm_set1_pd(1.0), zeros = _mm_setzero_pd();
  const __m128d one_zero = _mm_set_pd(0.0, 1.0);  // (1, 0) in memory order
  const __m128d zero_one = _mm_set_pd(1.0, 0.0);  // (0, 1)
  // Row i = (C0_i, C1_i, C2_i, e_i); vertex a (low lanes), then b.
  double* Jb = J + 18;
  _mm_storeu_pd(J + 0, _mm_unpacklo_pd(C[0][0], C[1][0]));
  _mm_storeu_pd(J + 2, _mm_unpacklo_pd(C[2][0], ones));
  _mm_storeu_pd(J + 4, zeros);
  _mm_storeu_pd(J + 6, _mm_unpacklo_pd(C[0][1], C[1][1]));
  _mm_storeu_pd(J + 8, _mm_unpacklo_pd(C[2][1], zeros));
  _mm_storeu_pd(J + 10, one_zero);
  _mm_storeu_pd(J + 12, _mm_unpacklo_pd(C[0][2], C[1][2]));
  _mm_storeu_pd(J + 14, _mm_unpacklo_pd(C[2][2], zeros));
  _mm_storeu_pd(J + 16, zero_one);
  _mm_storeu_pd(Jb + 0, _mm_unpackhi_pd(C[0][0], C[1][0]));
  _mm_storeu_pd(Jb + 2, _mm_unpackhi_pd(C[2][0], ones));
  _mm_storeu_pd(Jb + 4, zeros);
  _mm_storeu_pd(Jb + 6, _mm_unpackhi_pd(C[0][1], C[1][1]));
  _mm_storeu_pd(Jb + 8, _mm_unpackhi_pd(C[2][1], zeros));
  _mm_storeu_pd(Jb + 10, one_zero);
  _mm_storeu_pd(Jb + 12, _mm_unpackhi_pd(C[0][2], C[1][2]));
  _mm_storeu_pd(Jb + 14, _mm_unpackhi_pd(C[2][2], zeros));
  _mm_storeu_pd(Jb + 16, zero_one);
}

/// Non-temporal copy of `count` (even) doubles; both pointers 16-byte aligned.
inline void streamCopy(double* out, const double* in, std::size_t count)
{
  for (std::size_t i = 0; i < count; i += 2)
    _mm_stream_pd(out + i, _mm_load_pd(in + i));
}

/// vertexPositionsAndJacobians in double, two vertices per SSE2 register
/// (the same bits as the portable loop). With Stream (outputs 16-byte
/// aligned), blocks of 16 vertices are computed into an L1 buffer and then
/// streamed out whole-line by whole-line: non-temporal stores interleaved
/// with the arithmetic leave write-combining buffers half full and are
/// slower than ordinary stores.
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
  {
    const Vector3<double> lever = rotate(pose.R, Eigen::Map<const Vector3<double>>(vertex(n)));
    if (positions)
      for (int i = 0; i < 3; ++i)
        positions[3 * n + i] = lever[i] + pose.t[i];
    double* J = jacobians + 18 * n;
    for (int c = 0; c < 3; ++c)
    {
      const Vector3<double> column = cross(pose.T.col(c), lever);
      J[c] = column[0];
      J[6 + c] = column[1];
      J[12 + c] = column[2];
    }
    J[3] = 1.0, J[4] = 0.0, J[5] = 0.0, J[9] = 0.0, J[10] = 1.0, J[11] = 0.0, J[15] = 0.0, J[16] = 0.0, J[17] = 1.0;
  }
}

#if defined(DRB_VERTEX_KERNELS_AVX2)
/// true when the CPU has AVX2 and FMA (checked once).
inline bool cpuHasAvx2Fma()
{
  static const bool has = [] {
    __builtin_cpu_init();
    return __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma");
  }();
  return has;
}

/// Four vertices stored as rows r0 = (x0 y0 z0 x1), r1 = (y1 z1 x2 y2),
/// r2 = (z2 x3 y3 z3), transposed into lanes: out = (x0..3), (y0..3), (z0..3).
__attribute__((target("avx2,fma"))) inline void transpose4Vertices(const double* v, __m256d* out)
{
  const __m256d r0 = _mm256_loadu_pd(v), r1 = _mm256_loadu_pd(v + 4), r2 = _mm256_loadu_pd(v + 8);
  out[0] = _mm256_permute4x64_pd(_mm256_blend_pd(_mm256_blend_pd(r0, r1, 0x4), r2, 0x2), 0x6C);
  out[1] = _mm256_permute4x64_pd(_mm256_blend_pd(_mm256_blend_pd(r0, r1, 0x9), r2, 0x4), 0xB1);
  out[2] = _mm256_permute4x64_pd(_mm256_blend_pd(_mm256_blend_pd(r0, r1, 0x2), r2, 0x9), 0xC6);
}

/// The first 4 floor(count / 4) vertices of the contiguous backprop sum,
/// four vertices per AVX2 register, one FMA per product. Adds the 12 sums
/// (W row-major, then force) to `sums`; returns the vertices done.
__attribute__((target("avx2,fma"))) inline std::size_t sumOuterProductsAvx2(const double* p, const double* g,
                                                                            std::size_t count, double* sums)
{
  __m256d acc[12];
  for (__m256d& a : acc)
    a = _mm256_setzero_pd();
  std::size_t n = 0;
  for (; n + 4 <= count; n += 4)
  {
    __m256d P[3], G[3];
    transpose4Vertices(p + 3 * n, P);
    transpose4Vertices(g + 3 * n, G);
    for (int i = 0; i < 3; ++i)
    {
      for (int j = 0; j < 3; ++j)
        acc[3 * i + j] = _mm256_fmadd_pd(G[i], P[j], acc[3 * i + j]);
      acc[9 + i] = _mm256_add_pd(acc[9 + i], G[i]);
    }
  }
  for (int k = 0; k < 12; ++k)
  {
    double lanes[4];
    _mm256_storeu_pd(lanes, acc[k]);
    sums[k] += (lanes[0] + lanes[1]) + (lanes[2] + lanes[3]);
  }
  return n;
}
#endif

/// sum_i g_i p0_i^T (row-major 3x3, out W) and sum_i g_i (out force) in
/// double, two vertices per SSE2 register with their coordinates
/// transposed into lanes: 9 products and 12 sums per pair of vertices,
/// instead of per vertex. Contiguous vertices (no index list) go four per
/// AVX2 register when the CPU has AVX2 and FMA.
inline void sumOuterProducts(const Matrix3X<double>& vertices, const std::vector<std::uint32_t>& indices,
                             const double* gradients, double* W, double* force)
{
  const bool all = indices.empty();
  const std::size_t count = all ? static_cast<std::size_t>(vertices.cols()) : indices.size();
  const double* base = vertices.data();
  double wide[12] = {};  // the AVX2 part's sums
  std::size_t n = 0;
#if defined(DRB_VERTEX_KERNELS_AVX2)
  if (all && count >= 4 && cpuHasAvx2Fma())
    n = sumOuterProductsAvx2(base, gradients, count, wide);
#endif
  __m128d acc[12];
  for (__m128d& a : acc)
    a = _mm_setzero_pd();
  for (; n + 2 <= count; n += 2)
  {
    // Lanes (vertex n, vertex n + 1).
    __m128d P0, P1, P2;
    if (all)
    {
      const double* p = base + 3 * n;
      const __m128d a01 = _mm_loadu_pd(p), a2b0 = _mm_loadu_pd(p + 2), b12 = _mm_loadu_pd(p + 4);
      P0 = _mm_shuffle_pd(a01, a2b0, 0x2);
      P1 = _mm_shuffle_pd(a01, b12, 0x1);
      P2 = _mm_shuffle_pd(a2b0, b12, 0x2);
    }
    else
    {
      const double* pa = base + 3 * static_cast<std::size_t>(indices[n]);
      const double* pb = base + 3 * static_cast<std::size_t>(indices[n + 1]);
      P0 = _mm_loadh_pd(_mm_load_sd(pa), pb);
      P1 = _mm_loadh_pd(_mm_load_sd(pa + 1), pb + 1);
      P2 = _mm_loadh_pd(_mm_load_sd(pa + 2), pb + 2);
    }
    const double* g = gradients + 3 * n;
    const __m128d g01 = _mm_loadu_pd(g), g2h0 = _mm_loadu_pd(g + 2), h12 = _mm_loadu_pd(g + 4);
    const __m128d G0 = _mm_shuffle_pd(g01, g2h0, 0x2);
    const __m128d G1 = _mm_shuffle_pd(g01, h12, 0x1);
    const __m128d G2 = _mm_shuffle_pd(g2h0, h12, 0x2);
    acc[0] = _mm_add_pd(acc[0], _mm_mul_pd(G0, P0));
    acc[1] = _mm_add_pd(acc[1], _mm_mul_pd(G0, P1));
    acc[2] = _mm_add_pd(acc[2], _mm_mul_pd(G0, P2));
    acc[3] = _mm_add_pd(acc[3], _mm_mul_pd(G1, P0));
    acc[4] = _mm_add_pd(acc[4], _mm_mul_pd(G1, P1));
    acc[5] = _mm_add_pd(acc[5], _mm_mul_pd(G1, P2));
    acc[6] = _mm_add_pd(acc[6], _mm_mul_pd(G2, P0));
    acc[7] = _mm_add_pd(acc[7], _mm_mul_pd(G2, P1));
    acc[8] = _mm_add_pd(acc[8], _mm_mul_pd(G2, P2));
    acc[9] = _mm_add_pd(acc[9], G0);
    acc[10] = _mm_add_pd(acc[10], G1);
    acc[11] = _mm_add_pd(acc[11], G2);
  }
  double sums[12];
  for (int k = 0; k < 12; ++k)
  {
    double lanes[2];
    _mm_storeu_pd(lanes, acc[k]);
    sums[k] = wide[k] + (lanes[0] + lanes[1]);
  }
  if (n < count)  // an odd last vertex
  {
    const double* p = base + 3 * (all ? n : static_cast<std::size_t>(indices[n]));
    const double* g = gradients + 3 * n;
    for (int i = 0; i < 3; ++i)
    {
      for (int j = 0; j < 3; ++j)
        sums[3 * i + j] += g[i] * p[j];
      sums[9 + i] += g[i];
    }
  }
  for (int k = 0; k < 9; ++k)
    W[k] = sums[k];
  for (int k = 0; k < 3; ++k)
    force[k] = sums[9 + k];
}
}  // namespace detail
#endif

/// Positions (3 per vertex) and Jacobians (18 per vertex, 3x6 row-major) for
/// the selected vertices, written to caller-owned buffers.
///
/// \param vertices  body-frame vertices, one per column [m]
/// \param indices   vertices to evaluate; empty means all, in order. Indices
///                  must already be validated (< vertices.cols()).
/// \param positions out, 3 * count values, or nullptr to skip
/// \param jacobians out, 18 * count values, or nullptr to skip
template <typename Scalar>
void vertexPositionsAndJacobians(const BodyPose<Scalar>& pose, const Matrix3X<Scalar>& vertices,
                                 const std::vector<std::uint32_t>& indices, Scalar* positions, Scalar* jacobians)
{
  const bool all = indices.empty();
  const std::size_t count = all ? static_cast<std::size_t>(vertices.cols()) : indices.size();
#if defined(DRB_VERTEX_KERNELS_SSE2)
  if constexpr (std::is_same<Scalar, double>::value)
  {
    if (jacobians)
    {
      const bool aligned = reinterpret_cast<std::uintptr_t>(jacobians) % 16 == 0 &&
                           reinterpret_cast<std::uintptr_t>(positions) % 16 == 0;  // null is aligned
      if (aligned && 18 * sizeof(double) * count >= kStreamingStoreBytes)
        detail::positionsAndJacobiansSse2<true>(pose, vertices, indices, positions, jacobians);
      else
        detail::positionsAndJacobiansSse2<false>(pose, vertices, indices, positions, jacobians);
      return;
    }
  }
#endif
  const Matrix3<Scalar>& R = pose.R;
  const Matrix3<Scalar>& T = pose.T;
  for (std::size_t n = 0; n < count; ++n)
  {
    const Eigen::Index v = all ? static_cast<Eigen::Index>(n) : static_cast<Eigen::Index>(indices[n]);
    const Vector3<Scalar> lever = detail::rotate(R, vertices.col(v));
    if (positions)
    {
      Scalar* p = positions + 3 * n;
      p[0] = lever[0] + pose.t[0];
      p[1] = lever[1] + pose.t[1];
      p[2] = lever[2] + pose.t[2];
    }
    if (jacobians)
    {
      // Row-major 3x6: row i = (d p_i / d r_0..2, e_i).
      Scalar* J = jacobians + 18 * n;
      for (int k = 0; k < 3; ++k)
      {
        const Vector3<Scalar> column = detail::cross(T.col(k), lever);
        J[k] = column[0];
        J[6 + k] = column[1];
        J[12 + k] = column[2];
      }
      J[3] = Scalar(1), J[4] = Scalar(0), J[5] = Scalar(0);
      J[9] = Scalar(0), J[10] = Scalar(1), J[11] = Scalar(0);
      J[15] = Scalar(0), J[16] = Scalar(0), J[17] = Scalar(1);
    }
  }
}

/// Reduced transport of vertexPositionsAndJacobians: J = [ Jr | I3 ] always
/// has the identity as its translation block, so only the rotation block
/// Jr = dp/d(phi, theta, psi) is written, 9 values per vertex (3x3
/// row-major: row i = dp_i/d(phi, theta, psi)). Computed in Scalar and
/// stored as Out (e.g. float for a float32 transport); the values equal
/// those of vertexPositionsAndJacobians before the conversion.
///
/// \param positions          out, 3 * count values, or nullptr to skip
/// \param rotation_jacobians out, 9 * count values, or nullptr to skip
template <typename Scalar, typename Out>
void vertexPositionsAndRotationJacobians(const BodyPose<Scalar>& pose, const Matrix3X<Scalar>& vertices,
                                         const std::vector<std::uint32_t>& indices, Out* positions,
                                         Out* rotation_jacobians)
{
  const bool all = indices.empty();
  const std::size_t count = all ? static_cast<std::size_t>(vertices.cols()) : indices.size();
  const Matrix3<Scalar>& R = pose.R;
  const Matrix3<Scalar>& T = pose.T;
  for (std::size_t n = 0; n < count; ++n)
  {
    const Eigen::Index v = all ? static_cast<Eigen::Index>(n) : static_cast<Eigen::Index>(indices[n]);
    const Vector3<Scalar> lever = detail::rotate(R, vertices.col(v));
    if (positions)
    {
      Out* p = positions + 3 * n;
      p[0] = static_cast<Out>(lever[0] + pose.t[0]);
      p[1] = static_cast<Out>(lever[1] + pose.t[1]);
      p[2] = static_cast<Out>(lever[2] + pose.t[2]);
    }
    if (rotation_jacobians)
    {
      Out* J = rotation_jacobians + 9 * n;
      for (int k = 0; k < 3; ++k)
      {
        const Vector3<Scalar> column = detail::cross(T.col(k), lever);
        J[k] = static_cast<Out>(column[0]);
        J[3 + k] = static_cast<Out>(column[1]);
        J[6 + k] = static_cast<Out>(column[2]);
      }
    }
  }
}

/// dL/dq from the two per-body sums of the backprop (see the top of this
/// file): W = sum_i g_i p0_i^T and force = sum_i g_i.
///   dL/dr = T^T (X12 - X21, X20 - X02, X01 - X10) with X = R W^T,
///   dL/dt = force.
template <typename Scalar>
Vector6<Scalar> backpropFromSums(const BodyPose<Scalar>& pose, const Matrix3<Scalar>& W, const Vector3<Scalar>& force)
{
  const Matrix3<Scalar> X = pose.R * W.transpose();  // sum_i (R p0_i) g_i^T
  const Vector3<Scalar> torque(X(1, 2) - X(2, 1), X(2, 0) - X(0, 2), X(0, 1) - X(1, 0));
  Vector6<Scalar> dL_dq;
  dL_dq.template head<3>() = pose.T.transpose() * torque;
  dL_dq.template tail<3>() = force;
  return dL_dq;
}

/// dL/dq = sum_i J_i^T g_i without forming J.
///
/// \param gradients dL/dp for each selected vertex, 3 per vertex, in the
///                  order of `indices` (or of all vertices when empty).
template <typename Scalar>
Vector6<Scalar> backpropagateVertexGradients(const BodyPose<Scalar>& pose, const Matrix3X<Scalar>& vertices,
                                             const std::vector<std::uint32_t>& indices, const Scalar* gradients)
{
  const bool all = indices.empty();
  const std::size_t count = all ? static_cast<std::size_t>(vertices.cols()) : indices.size();
  Matrix3<Scalar> W = Matrix3<Scalar>::Zero();  // sum_i g_i p0_i^T
  Vector3<Scalar> force = Vector3<Scalar>::Zero();  // sum_i g_i
#if defined(DRB_VERTEX_KERNELS_SSE2)
  if constexpr (std::is_same<Scalar, double>::value)
  {
    Eigen::Matrix<double, 3, 3, Eigen::RowMajor> W_rows;
    detail::sumOuterProducts(vertices, indices, gradients, W_rows.data(), force.data());
    W = W_rows;
  }
  else
#endif
  {
    for (std::size_t n = 0; n < count; ++n)
    {
      const Eigen::Index v = all ? static_cast<Eigen::Index>(n) : static_cast<Eigen::Index>(indices[n]);
      const Eigen::Map<const Vector3<Scalar>> g(gradients + 3 * n);
      W.noalias() += g * vertices.col(v).transpose();
      force += g;
    }
  }
  return backpropFromSums(pose, W, force);
}

}  // namespace diff_rigid_body
