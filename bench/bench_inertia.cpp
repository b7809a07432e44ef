// Inertia, speed against error: the particle sum (particleMassProperties;
// docs/derivation.md, "Inertia") at N = 10^2 .. 10^6 samples against the
// exact polyhedral integral (meshMassProperties), on the Stanford bunny and
// armadillo of test/meshes/stanford. Writes JSON to argv[1] (or stdout).
//
// Errors (density 1000 kg/m^3; the mesh in its own frame):
//   mass     |m_N - m| / m
//   com      |c_N - c| / bounding-box diagonal
//   inertia  max|I_N - I| / max|I|   (about the COM)
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>

#include "bench_common.h"
#include "diff_rigid_body/mass/mass_properties.h"
#include "reference/particle_mass_properties.h"

namespace
{
using namespace drb_bench;
using Clock = std::chrono::steady_clock;

/// Median-of-runs wall time of f(), repeating until ~budget seconds.
template <typename F>
double timeIt(F&& f, double budget)
{
  std::vector<double> runs;
  const auto start = Clock::now();
  do
  {
    const auto t0 = Clock::now();
    f();
    runs.push_back(std::chrono::duration<double>(Clock::now() - t0).count());
  } while (std::chrono::duration<double>(Clock::now() - start).count() < budget && runs.size() < 1000);
  std::sort(runs.begin(), runs.end());
  return runs[runs.size() / 2];
}
}  // namespace

int main(int argc, char** argv)
{
  const double density = 1000.0;
  const double budget = argc > 2 ? std::atof(argv[2]) : 0.3;
  std::FILE* out = argc > 1 ? std::fopen(argv[1], "w") : stdout;
  if (!out)
  {
    std::perror(argv[1]);
    return 1;
  }
  std::fprintf(out, "{\"density\": %g, \"meshes\": [\n", density);
  const std::vector<std::string> names = { "bunny", "armadillo" };
  for (std::size_t m = 0; m < names.size(); ++m)
  {
    const NamedMesh named = stanfordMesh(names[m]);
    const drb::TriangleMesh& mesh = named.mesh;
    drb::MassProperties exact;
    const double exact_time = timeIt([&] { exact = drb::meshMassProperties(density, mesh, named.name); }, budget);
    const double diagonal = (mesh.vertices.rowwise().maxCoeff() - mesh.vertices.rowwise().minCoeff()).norm();
    const double inertia_scale = exact.inertia.cwiseAbs().maxCoeff();
    std::fprintf(out,
                 "  {\"name\": \"%s\", \"vertices\": %ld, \"triangles\": %zu, "
                 "\"exact_seconds\": %.6g, \"mass\": %.17g, \"points\": [\n",
                 named.name.c_str(), static_cast<long>(mesh.vertices.cols()),
                 mesh.triangles.size(), exact_time, exact.mass);
    const std::vector<std::size_t> targets = { 100, 316, 1000, 3162, 10000, 31623, 100000, 316228, 1000000 };
    for (std::size_t k = 0; k < targets.size(); ++k)
    {
      drb::ParticleMassProperties particles;
      const double seconds =
          timeIt([&] { particles = drb::particleMassProperties(density, mesh, targets[k], named.name); }, budget);
      const drb::MassProperties& p = particles.mass_properties;
      const double mass_error = std::abs(p.mass - exact.mass) / exact.mass;
      const double com_error = (p.com - exact.com).norm() / diagonal;
      const double inertia_error = (p.inertia - exact.inertia).cwiseAbs().maxCoeff() / inertia_scale;
      std::fprintf(out,
                   "    {\"target\": %zu, \"samples\": %zu, \"seconds\": %.6g, \"mass_error\": %.6g, "
                   "\"com_error\": %.6g, \"inertia_error\": %.6g}%s\n",
                   targets[k], particles.num_samples, seconds, mass_error, com_error, inertia_error,
                   k + 1 < targets.size() ? "," : "");
      std::fflush(out);
    }
    std::fprintf(out, "  ]}%s\n", m + 1 < names.size() ? "," : "");
  }
  std::fprintf(out, "]}\n");
  if (out != stdout)
    std::fclose(out);
  return 0;
}
