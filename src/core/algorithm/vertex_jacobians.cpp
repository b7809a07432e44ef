#include "diff_rigid_body/algorithm/vertex_jacobians.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

#include "diff_rigid_body/algorithm/detail/cpu_features.h"
#include "diff_rigid_body/algorithm/free_body/vertex_jacobian.h"
#include "diff_rigid_body/algorithm/kinematics.h"
#include "algorithm/segment_columns.h"

namespace diff_rigid_body
{
using detail::prepareSegmentColumns;

JacobianColumns JacobianColumns::all(const BodyModel& model)
{
  JacobianColumns columns;
  for (std::size_t c = 0; c < model.coordinates; ++c)
    columns.of_coordinate.push_back(static_cast<int>(c));
  columns.width = model.coordinates;
  return columns;
}

JacobianColumns JacobianColumns::compact(const BodyModel& model)
{
  JacobianColumns columns;
  const bool free_root = model.hasFreeRoot();
  for (std::size_t c = 0; c < model.coordinates; ++c)
  {
    const bool translation = free_root && c >= TX && c <= TZ;
    columns.of_coordinate.push_back(translation ? -1 : static_cast<int>(columns.width));
    columns.width += translation ? 0 : 1;
  }
  return columns;
}

namespace
{
// Rounding in R p0 and the norm behind a vertex radius r adds less than
// 20 eps r; with r inflated by 64 eps a bound rounded to nearest stays above
// every output (free_body: |t|_inf + kInflation r, as version 1 checked it).
constexpr double kInflation = 1.0 + 64 * std::numeric_limits<double>::epsilon();

/// The bound of vertexOutputBound for segment s, its columns prepared.
double segmentBound(const BodyModel& model, const BodyWorkspace<double>& ws, std::size_t width, std::size_t s)
{
  const double radius = kInflation * model.segments[s].vertex_radius;
  const double lever = (ws.p[s] - ws.r).norm() + radius;
  const double* rows = ws.column_motion.data();
  double bound = ws.p[s].cwiseAbs().maxCoeff() + radius;
  for (std::size_t c = 0; c < width; ++c)
  {
    const double v = std::hypot(rows[c], rows[width + c], rows[2 * width + c]);
    const double w = std::hypot(rows[3 * width + c], rows[4 * width + c], rows[5 * width + c]);
    bound = std::max(bound, (v + w * lever) * kInflation);
  }
  return bound;
}

// Positions p = R p0 + p_s and J rows of `count` vertices of one segment
// (p0 one per column of `vertices`, 3 apart), written from P and J on.
// Row i of J = V + W x d, d = p - r, column by column:
// (W x d)_x = W_y d_z - W_z d_y, and cyclically. One body for every target,
// and for a width known at compile time (1 to 16 columns, the common robots:
// the loops unroll) or not: GCC vectorises the columns with the lanes the
// target has.
#define DRB_SEGMENT_VERTICES_BODY                                                                                  \
  const std::size_t width = Width > 0 ? std::size_t(Width) : runtime_width;                                        \
  const double* __restrict__ V = motion.V;                                                                         \
  const double* __restrict__ Wx = V + 3 * width;                                                                   \
  const double* __restrict__ Wy = Wx + width;                                                                      \
  const double* __restrict__ Wz = Wy + width;                                                                      \
  const double* R = motion.R;                                                                                      \
  for (std::size_t n = 0; n < count; ++n)                                                                          \
  {                                                                                                                \
    const double* p0 = vertices + 3 * n;                                                                           \
    double d[3];                                                                                                   \
    for (int i = 0; i < 3; ++i)                                                                                    \
    {                                                                                                              \
      const double p = ((R[i] * p0[0] + R[3 + i] * p0[1]) + R[6 + i] * p0[2]) + motion.p[i];                       \
      P[3 * n + i] = static_cast<Out>(p);                                                                          \
      d[i] = p - motion.r[i];                                                                                      \
    }                                                                                                              \
    if (!J)                                                                                                        \
      continue;                                                                                                    \
    Out* __restrict__ Jx = J + 3 * width * n;                                                                      \
    Out* __restrict__ Jy = Jx + width;                                                                             \
    Out* __restrict__ Jz = Jy + width;                                                                             \
    for (std::size_t c = 0; c < width; ++c)                                                                        \
      Jx[c] = static_cast<Out>(V[c] + (d[2] * Wy[c] - d[1] * Wz[c]));                                              \
    for (std::size_t c = 0; c < width; ++c)                                                                        \
      Jy[c] = static_cast<Out>(V[width + c] + (d[0] * Wz[c] - d[2] * Wx[c]));                                      \
    for (std::size_t c = 0; c < width; ++c)                                                                        \
      Jz[c] = static_cast<Out>(V[2 * width + c] + (d[1] * Wx[c] - d[0] * Wy[c]));                                  \
  }

/// One segment's pose and prepared columns, as the kernels read them.
struct SegmentMotion
{
  const double* R;  ///< 3 x 3, column-major
  const double* p;  ///< its origin
  const double* r;  ///< the reference point
  const double* V;  ///< rows V_x, V_y, V_z, W_x, W_y, W_z, width apart
};

template <int Width, typename Out>
void segmentVertices(const SegmentMotion& motion, std::size_t runtime_width, const double* __restrict__ vertices,
                     std::size_t count, Out* __restrict__ P, Out* __restrict__ J)
{
  DRB_SEGMENT_VERTICES_BODY
}

#undef DRB_SEGMENT_VERTICES_BODY

#if defined(DRB_VERTEX_KERNELS_AVX2)
/// The same in double with AVX2 + FMA, four columns per register, then two
/// (SSE registers) and one (scalar): masked AVX stores are slow on some
/// CPUs. J row x = V_x + d_z W_y - d_y W_z, etc.
__attribute__((target("avx2,fma"))) void segmentVerticesAvx2(const SegmentMotion& motion, std::size_t width,
                                                              const double* __restrict__ vertices, std::size_t count,
                                                              double* __restrict__ P, double* __restrict__ J)
{
  const double* V = motion.V;
  const double* R = motion.R;
  const std::size_t full = width & ~std::size_t(3), pair = width & ~std::size_t(1);
  for (std::size_t n = 0; n < count; ++n)
  {
    const double* p0 = vertices + 3 * n;
    double d[3];
    for (int i = 0; i < 3; ++i)
    {
      const double p = ((R[i] * p0[0] + R[3 + i] * p0[1]) + R[6 + i] * p0[2]) + motion.p[i];
      P[3 * n + i] = p;
      d[i] = p - motion.r[i];
    }
    if (!J)
      continue;
    double* Jn = J + 3 * width * n;
#define DRB_JACOBIAN_ROWS(VEC, SET1, LOAD, STORE, FMADD, FNMADD)                                                   \
  {                                                                                                                \
    const VEC dx = SET1(d[0]), dy = SET1(d[1]), dz = SET1(d[2]);                                                   \
    const VEC Wx = LOAD(V + 3 * width + c), Wy = LOAD(V + 4 * width + c), Wz = LOAD(V + 5 * width + c);            \
    STORE(Jn + c, FMADD(dz, Wy, FNMADD(dy, Wz, LOAD(V + c))));                                                     \
    STORE(Jn + width + c, FMADD(dx, Wz, FNMADD(dz, Wx, LOAD(V + width + c))));                                     \
    STORE(Jn + 2 * width + c, FMADD(dy, Wx, FNMADD(dx, Wy, LOAD(V + 2 * width + c))));                             \
  }
    std::size_t c = 0;
    for (; c < full; c += 4)
      DRB_JACOBIAN_ROWS(__m256d, _mm256_set1_pd, _mm256_loadu_pd, _mm256_storeu_pd, _mm256_fmadd_pd, _mm256_fnmadd_pd)
    if (c < pair)
    {
      DRB_JACOBIAN_ROWS(__m128d, _mm_set1_pd, _mm_loadu_pd, _mm_storeu_pd, _mm_fmadd_pd, _mm_fnmadd_pd)
      c += 2;
    }
#undef DRB_JACOBIAN_ROWS
    if (c < width)  // the same with one fused multiply-add per term, as the lanes above
    {
      Jn[c] = std::fma(d[2], V[4 * width + c], std::fma(-d[1], V[5 * width + c], V[c]));
      Jn[width + c] = std::fma(d[0], V[5 * width + c], std::fma(-d[2], V[3 * width + c], V[width + c]));
      Jn[2 * width + c] = std::fma(d[1], V[3 * width + c], std::fma(-d[0], V[4 * width + c], V[2 * width + c]));
    }
  }
}
#endif

template <typename Out>
using SegmentVerticesKernel = void (*)(const SegmentMotion&, std::size_t, const double*, std::size_t, Out*, Out*);

/// The kernel for `width` columns on this CPU.
template <typename Out, int... Widths>
SegmentVerticesKernel<Out> segmentVerticesKernel(std::size_t width, std::integer_sequence<int, Widths...>)
{
#if defined(DRB_VERTEX_KERNELS_AVX2)
  if constexpr (std::is_same<Out, double>::value)
    if (detail::cpuHasAvx2Fma())
      return &segmentVerticesAvx2;
#endif
  SegmentVerticesKernel<Out> kernel = nullptr;
  ((kernel = width == std::size_t(Widths) ? &segmentVertices<Widths, Out> : kernel), ...);
  return kernel ? kernel : &segmentVertices<0, Out>;
}

template <typename Out>
SegmentVerticesKernel<Out> segmentVerticesKernel(std::size_t width)
{
  return segmentVerticesKernel<Out>(width, std::integer_sequence<int, 1, 2, 3, 4, 5, 6, 7, 8>());
}

SegmentMotion segmentMotion(const BodyWorkspace<double>& ws, std::size_t s)
{
  return { ws.R[s].data(), ws.p[s].data(), ws.r.data(), ws.column_motion.data() };
}

/// A free object's outputs by the closed forms: J whole (18 per vertex) or
/// its rotation block (9, the compact columns).
template <typename Out>
void freeObjectVertexJacobians(const BodyModel& model, const JacobianColumns& columns,
                               const std::vector<std::uint32_t>& vertices, const double* x, Out* positions,
                               Out* jacobians)
{
  const BodyPose<double> pose{ Eigen::Map<const Vector6<double>>(x) };
  if constexpr (std::is_same<Out, double>::value)
    if (columns.width == 6)
    {
      vertexPositionsAndJacobians(pose, model.vertices, vertices, positions, jacobians);
      return;
    }
  vertexPositionsAndRotationJacobians(pose, model.vertices, vertices, positions, jacobians);
}
}  // namespace

double vertexOutputBound(const BodyModel& model, BodyWorkspace<double>& ws, const JacobianColumns& columns,
                         const std::vector<std::uint32_t>& vertices, const double* x)
{
  if (model.closedFormKernels())
    return std::max({ std::abs(x[TX]), std::abs(x[TY]), std::abs(x[TZ]) }) +
           kInflation * model.segments[0].vertex_radius;
  forwardKinematics(model, ws, x);
  if (!kinematicsAreFinite(model, ws))
    return std::numeric_limits<double>::infinity();
  std::fill(ws.segment_selected.begin(), ws.segment_selected.end(), vertices.empty() ? 1 : 0);
  for (std::uint32_t v : vertices)
    ws.segment_selected[model.segmentOfVertex(v)] = 1;
  double bound = 0.0;
  for (std::size_t s = 0; s < model.segments.size(); ++s)
    if (ws.segment_selected[s] && model.segments[s].vertex_count > 0)
    {
      prepareSegmentColumns(model, ws, columns, s);
      bound = std::max(bound, segmentBound(model, ws, columns.width, s));
    }
  return bound;
}

template <typename Out>
void vertexJacobians(const BodyModel& model, BodyWorkspace<double>& ws, const JacobianColumns& columns,
                     const std::vector<std::uint32_t>& vertices, const double* x, Out* positions, Out* jacobians)
{
  if (model.closedFormKernels())
  {
    freeObjectVertexJacobians(model, columns, vertices, x, positions, jacobians);
    return;
  }
  forwardKinematics(model, ws, x);
  const std::size_t width = columns.width;
  Out* const no_jacobians = nullptr;
  const SegmentVerticesKernel<Out> kernel = segmentVerticesKernel<Out>(width);
  if (vertices.empty())
  {
    for (std::size_t s = 0; s < model.segments.size(); ++s)
    {
      const Segment& segment = model.segments[s];
      if (segment.vertex_count == 0)
        continue;
      prepareSegmentColumns(model, ws, columns, s);
      const std::size_t first = segment.vertex_begin;
      kernel(segmentMotion(ws, s), width, model.vertices.col(segment.vertex_begin).data(), segment.vertex_count,
             positions + 3 * first, jacobians ? jacobians + 3 * width * first : no_jacobians);
    }
    return;
  }
  std::size_t prepared = model.segments.size();
  for (std::size_t slot = 0; slot < vertices.size(); ++slot)
  {
    const std::size_t s = model.segmentOfVertex(vertices[slot]);
    if (s != prepared)
      prepareSegmentColumns(model, ws, columns, prepared = s);
    kernel(segmentMotion(ws, s), width, model.vertices.col(vertices[slot]).data(), 1, positions + 3 * slot,
           jacobians ? jacobians + 3 * width * slot : no_jacobians);
  }
}

template void vertexJacobians<double>(const BodyModel&, BodyWorkspace<double>&, const JacobianColumns&,
                                      const std::vector<std::uint32_t>&, const double*, double*, double*);
template void vertexJacobians<float>(const BodyModel&, BodyWorkspace<double>&, const JacobianColumns&,
                                     const std::vector<std::uint32_t>&, const double*, float*, float*);

}  // namespace diff_rigid_body
