// Maximum relative error of every benchmarked method against a 256-bit MPFR
// reference (our scalar-templated kernels evaluated in mpfr::mpreal, which
// test_core checks against an independent mpreal evaluation), over the
// hard-case state set of docs/derivation.md ("Hard cases"). Writes JSON to
// argv[1] (or stdout).
//
// Error measures (the difference is taken in 256 bits, then rounded):
//   mass matrix  max over the four 3x3 blocks of max|dM| / s, with s the
//                largest |entry| of the reference angular block, m for the
//                translational block and sqrt(s m) for the cross blocks
//                (which are zero);
//   Jacobian     max(max|dJr| / max|Jr|, max|dJt|) per vertex (Jr rotation
//                block, Jt = I3 the translation block);
//   backprop     |d(dL/dr)|_inf / sum_i |p0_i||g_i| and
//                |d(dL/dt)|_inf / sum_i |g_i| (scale of the summed terms).
#include <cstdio>
#include <map>
#include <random>
#include <string>

#include <mpreal.h>

#include "bench_common.h"
#include "memory_floors.h"
#include "methods.h"

namespace
{
using namespace drb_bench;
using mpfr::mpreal;
using MatrixMp3 = Eigen::Matrix<mpreal, 3, 3>;
using MatrixMp6 = Eigen::Matrix<mpreal, 6, 6>;
using VectorMp6 = Eigen::Matrix<mpreal, 6, 1>;
using VectorMp3 = Eigen::Matrix<mpreal, 3, 1>;

/// method -> tag -> max error; tag "all" is the overall maximum.
using Table = std::map<std::string, std::map<std::string, double>>;

void record(Table& table, const std::string& method, const std::string& tag, double error)
{
  for (const std::string& key : { tag, std::string("all") })
  {
    double& slot = table[method][key];
    if (!(error <= slot))  // NaN sticks
      slot = error;
  }
}

double diff(const mpreal& ours, const mpreal& ref)
{
  return mpfr::abs(ours - ref).toDouble();
}

/// Block-scaled error of a 36-value row-major M against the reference.
double massMatrixError(const double* M, const MatrixMp6& ref)
{
  double s = 0, m = ref(3, 3).toDouble();
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      s = std::max(s, std::abs(ref(i, j).toDouble()));
  double error = 0;
  for (int i = 0; i < 6; ++i)
    for (int j = 0; j < 6; ++j)
    {
      const double scale = (i < 3 && j < 3) ? s : (i >= 3 && j >= 3) ? m : std::sqrt(s * m);
      const double e = diff(mpreal(M[6 * i + j]), ref(i, j)) / scale;
      if (!(e <= error))
        error = e;
    }
  return error;
}

/// Error of an 18-value row-major J against the reference.
double jacobianError(const double* J, const Eigen::Matrix<mpreal, 3, 6>& ref)
{
  double scale = 0;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c)
      scale = std::max(scale, std::abs(ref(r, c).toDouble()));
  double error = 0;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 6; ++c)
    {
      const double e = diff(mpreal(J[6 * r + c]), ref(r, c)) / (c < 3 ? scale : 1.0);
      if (!(e <= error))
        error = e;
    }
  return error;
}

std::string vertexTag(double norm)
{
  char buffer[32];
  std::snprintf(buffer, sizeof(buffer), "vertex_%g_m", norm);
  return buffer;
}

void writeTable(std::FILE* out, const char* name, const Table& table, bool last)
{
  std::fprintf(out, "  \"%s\": {\n", name);
  std::size_t i = 0;
  for (const auto& [method, tags] : table)
  {
    std::fprintf(out, "    \"%s\": {", method.c_str());
    std::size_t j = 0;
    for (const auto& [tag, value] : tags)
      std::fprintf(out, "\"%s\": %.6g%s", tag.c_str(), value, ++j < tags.size() ? ", " : "");
    std::fprintf(out, "}%s\n", ++i < table.size() ? "," : "");
  }
  std::fprintf(out, "  }%s\n", last ? "" : ",");
}
}  // namespace

int main(int argc, char** argv)
{
  mpreal::set_default_prec(256);
  const std::vector<TaggedState> states = errorStates();
  const std::vector<TaggedBody> bodies = errorBodies();
  std::vector<double> norms;
  const Matrix3Xd vertices = errorVertices(&norms);
  const std::size_t nv = static_cast<std::size_t>(vertices.cols());

  // ---- Mass matrix.
  Table mass_table;
  for (const TaggedBody& b : bodies)
  {
    const mpreal m_mp(b.mass);
    const MatrixMp3 I_mp = b.inertia.cast<mpreal>();
#ifdef DRB_BENCH_HAVE_KDL
    KdlMassMatrix kdl(b.mass, b.inertia);
#endif
#ifdef DRB_BENCH_HAVE_MUJOCO
    MujocoBody mj(b.mass, b.inertia);
#endif
    const EnergyFiniteDifferences fd{ b.mass, b.inertia };
    std::vector<double> packed, batch(36 * states.size()), cos_theta(states.size());
    for (const TaggedState& s : states)
      packed.insert(packed.end(), s.q.data(), s.q.data() + 6);
    drb::massMatrixBatch(packed.data(), states.size(), 6, b.mass, b.inertia, batch.data(), cos_theta.data());
    const Eigen::Matrix3f I_f = b.inertia.cast<float>();
    for (std::size_t k = 0; k < states.size(); ++k)
    {
      const TaggedState& s = states[k];
      const MatrixMp6 ref = drb::massMatrix(VectorMp6(s.q.cast<mpreal>()), m_mp, I_mp);
      const std::string tag = s.tag + "/" + b.tag;
      double M[36];
      oursMassMatrix(s.q, b.mass, b.inertia, M);
      record(mass_table, "ours_double", tag, massMatrixError(M, ref));
      record(mass_table, "ours_batch_double", tag, massMatrixError(batch.data() + 36 * k, ref));
      // The node's single request: massMatrixBatch of one state.
      drb::massMatrixBatch(s.q.data(), 1, 6, b.mass, b.inertia, M);
      record(mass_table, "ours_batch_single", tag, massMatrixError(M, ref));
      const drb::Matrix6<float> Mf = drb::massMatrix(drb::Vector6<float>(s.q.cast<float>()),
                                                     static_cast<float>(b.mass), I_f);
      const Matrix6d Mfd = Mf.cast<double>();
      // float: the input itself is rounded to float (as a float user's is).
      record(mass_table, "ours_float", tag, massMatrixError(Mfd.data(), ref));
      fd(s.q, M);
      record(mass_table, "fd_energy", tag, massMatrixError(M, ref));
#ifdef DRB_BENCH_HAVE_KDL
      kdl(s.q, M);
      record(mass_table, "kdl", tag, massMatrixError(M, ref));
#endif
#ifdef DRB_BENCH_HAVE_MUJOCO
      mj.massMatrix(s.q, M);
      record(mass_table, "mujoco", tag, massMatrixError(M, ref));
#endif
    }
  }

  // ---- sin/cos of the batched kernel, absolute error.
  Table trig_table;
  {
    std::vector<double> angles;
    for (const TaggedState& s : states)
      angles.insert(angles.end(), s.q.data(), s.q.data() + 3);
    std::mt19937_64 rng(1);
    std::uniform_real_distribution<double> u(-1e6, 1e6);
    for (int i = 0; i < 4096; ++i)
      angles.push_back(i < 2048 ? u(rng) / 1e6 * 10 : u(rng));
    std::vector<double> sines(angles.size()), cosines(angles.size());
    drb::sinCos(angles.data(), angles.size(), sines.data(), cosines.data());
    for (std::size_t i = 0; i < angles.size(); ++i)
    {
      const mpreal a(angles[i]);
      record(trig_table, "sinCos", "sin", diff(mpreal(sines[i]), mpfr::sin(a)));
      record(trig_table, "sinCos", "cos", diff(mpreal(cosines[i]), mpfr::cos(a)));
      record(trig_table, "std", "sin", diff(mpreal(std::sin(angles[i])), mpfr::sin(a)));
      record(trig_table, "std", "cos", diff(mpreal(std::cos(angles[i])), mpfr::cos(a)));
    }
  }

  // ---- Jacobians.
  Table jac_table;
  {
#ifdef DRB_BENCH_HAVE_KDL
    KdlJacobians kdl;
#endif
#ifdef DRB_BENCH_HAVE_MUJOCO
    MujocoBody mj(1.0, Matrix3d::Identity());
#endif
    const CentralDifferences fd;
    const ComplexStep cs;
    const drb::Matrix3X<mpreal> vertices_mp = vertices.cast<mpreal>();
    const drb::Matrix3X<float> vertices_f = vertices.cast<float>();
    std::vector<double> J(18 * nv), rot(9 * nv);
    std::vector<float> Jf(18 * nv), rot_f(9 * nv);
    for (const TaggedState& s : states)
    {
      const drb::BodyPose<mpreal> pose_mp(VectorMp6(s.q.cast<mpreal>()));
      std::vector<Eigen::Matrix<mpreal, 3, 6>> ref(nv);
      for (std::size_t v = 0; v < nv; ++v)
        ref[v] = drb::vertexJacobian(pose_mp, VectorMp3(vertices_mp.col(static_cast<Eigen::Index>(v))));
      auto check = [&](const std::string& method, const double* out) {
        for (std::size_t v = 0; v < nv; ++v)
        {
          const double e = jacobianError(out + 18 * v, ref[v]);
          record(jac_table, method, s.tag, e);
          record(jac_table, method, vertexTag(norms[v]), e);
        }
      };
      const drb::BodyPose<double> pose(s.q);
      drb::vertexPositionsAndJacobians<double>(pose, vertices, {}, nullptr, J.data());
      check("ours_double", J.data());
      const drb::BodyPose<float> pose_f(drb::Vector6<float>(s.q.cast<float>()));
      drb::vertexPositionsAndJacobians<float>(pose_f, vertices_f, {}, nullptr, Jf.data());
      std::vector<double> Jfd(Jf.begin(), Jf.end());
      check("ours_float", Jfd.data());
      // Reduced transport: rotation block only, computed in double, sent as float32.
      drb::vertexPositionsAndRotationJacobians<double, float>(pose, vertices, {}, nullptr, rot_f.data());
      drb::vertexPositionsAndRotationJacobians<double, double>(pose, vertices, {}, nullptr, rot.data());
      std::vector<double> from_rot(18 * nv), from_rot_f(18 * nv);
      for (std::size_t v = 0; v < nv; ++v)
        for (int r = 0; r < 3; ++r)
          for (int c = 0; c < 6; ++c)
          {
            from_rot[18 * v + 6 * r + c] = c < 3 ? rot[9 * v + 3 * r + c] : (c - 3 == r ? 1.0 : 0.0);
            from_rot_f[18 * v + 6 * r + c] = c < 3 ? double(rot_f[9 * v + 3 * r + c]) : (c - 3 == r ? 1.0 : 0.0);
          }
      check("ours_rotation_block_double", from_rot.data());
      check("ours_rotation_block_float32_transport", from_rot_f.data());
      fd(s.q, vertices, J.data());
      check("central_diff", J.data());
      cs(s.q, vertices, J.data());
      check("complex_step", J.data());
#ifdef DRB_BENCH_HAVE_KDL
      kdl(s.q, vertices, J.data());
      check("kdl", J.data());
#endif
#ifdef DRB_BENCH_HAVE_MUJOCO
      mj.jacobians(s.q, vertices, J.data());
      check("mujoco", J.data());
#endif
    }
  }

  // ---- Backprop.
  Table bp_table;
  {
    std::mt19937_64 rng(17);
    std::normal_distribution<double> n01(0.0, 1.0);
    std::vector<double> g(3 * nv), buffer(18 * nv);
    for (double& x : g)
      x = n01(rng);
    double rot_scale = 0, trans_scale = 0;
    for (std::size_t v = 0; v < nv; ++v)
    {
      const double gn = Eigen::Map<const Eigen::Vector3d>(g.data() + 3 * v).norm();
      rot_scale += vertices.col(static_cast<Eigen::Index>(v)).norm() * gn;
      trans_scale += gn;
    }
    const drb::Matrix3X<mpreal> vertices_mp = vertices.cast<mpreal>();
    std::vector<mpreal> g_mp(g.begin(), g.end());
    const drb::VertexColumns<double> columns = vertices.transpose();
    std::vector<std::uint32_t> all_indices(nv);
    for (std::size_t v = 0; v < nv; ++v)
      all_indices[v] = static_cast<std::uint32_t>(v);
    for (const TaggedState& s : states)
    {
      const drb::BodyPose<mpreal> pose_mp(VectorMp6(s.q.cast<mpreal>()));
      const VectorMp6 ref = drb::backpropagateVertexGradients(pose_mp, vertices_mp, {}, g_mp.data());
      auto check = [&](const std::string& method, const Vector6d& out) {
        double e = 0;
        for (int i = 0; i < 6; ++i)
          e = std::max(e, diff(mpreal(out[i]), ref[i]) / (i < 3 ? rot_scale : trans_scale));
        record(bp_table, method, s.tag, e);
      };
      const drb::BodyPose<double> pose(s.q);
      check("ours_double", drb::backpropagateVertexGradients(pose, vertices, {}, g.data()));
      check("ours_columns", drb::backpropagateVertexGradients(pose, columns, g.data()));
      check("ours_index_list", drb::backpropagateVertexGradients(pose, columns, all_indices, g.data()));
#if defined(DRB_BENCH_SIMD_PATHS)
      for (SimdPath path : { SimdPath::sse2, SimdPath::avx2, SimdPath::avx512 })
        if (cpuHas(path))
          check(std::string("columns_on_") + pathName(path), backpropColumnsOnPath(path, pose, columns, g.data()));
#endif
      check("form_J_and_multiply", backpropFormJ(pose, vertices, g.data()));
      check("J_buffer_then_multiply", backpropViaBuffer(pose, vertices, g.data(), buffer.data()));
    }
  }

  std::FILE* out = argc > 1 ? std::fopen(argv[1], "w") : stdout;
  if (!out)
  {
    std::perror(argv[1]);
    return 1;
  }
  std::fprintf(out, "{\n  \"config\": {\"states\": %zu, \"bodies\": %zu, \"vertices\": %zu, \"mpfr_bits\": 256},\n",
               states.size(), bodies.size(), nv);
  writeTable(out, "mass_matrix", mass_table, false);
  writeTable(out, "sincos_abs", trig_table, false);
  writeTable(out, "jacobian", jac_table, false);
  writeTable(out, "backprop", bp_table, true);
  std::fprintf(out, "}\n");
  if (out != stdout)
    std::fclose(out);
  return 0;
}
