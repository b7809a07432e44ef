// SceneQueries::bodies (~get_bodies): what each body of the scene is, flattened
// body after body as srv/GetBodies.srv lays it out.
#include "diff_rigid_body/services/scene_queries.h"

namespace diff_rigid_body
{
namespace
{
/// Appends `matrix` row-major to `out`.
template <typename Matrix>
void appendRowMajor(const Matrix& matrix, std::vector<double>& out)
{
  for (Eigen::Index r = 0; r < matrix.rows(); ++r)
    for (Eigen::Index c = 0; c < matrix.cols(); ++c)
      out.push_back(matrix(r, c));
}

void appendLinks(const BodyModel& body, BodiesAnswer& answer)
{
  answer.link_counts.push_back(static_cast<std::uint32_t>(body.links.size()));
  for (const LinkInBody& link : body.links)
  {
    answer.link_names.push_back(link.name);
    answer.link_vertex_counts.push_back(link.new_vertex_count);
    answer.link_masses.push_back(link.mass_properties.mass);
    appendRowMajor(link.mass_properties.inertia, answer.link_inertias);
    appendRowMajor(link.mass_properties.com, answer.link_com_offsets);
  }
}
}  // namespace

void SceneQueries::bodies(const SceneState&, BodiesAnswer& answer) const
{
  answer = BodiesAnswer();
  answer.fixed_frame = scene_.fixed_frame;
  for (const BodyModel& body : scene_.bodies)
  {
    const Segment& root = body.segments.front();
    answer.names.push_back(body.name);
    answer.masses.push_back(body.mass());
    appendRowMajor(root.inertia.inertia, answer.inertias);
    appendRowMajor(body.rootComOffset(), answer.com_offsets);
    answer.vertex_counts.push_back(static_cast<std::uint32_t>(body.vertexCount()));
    answer.dofs.push_back(static_cast<std::uint32_t>(body.coordinates));
    answer.joint_counts.push_back(static_cast<std::uint32_t>(body.joint_names.size()));
    answer.joint_names.insert(answer.joint_names.end(), body.joint_names.begin(), body.joint_names.end());
    answer.joint_lower.insert(answer.joint_lower.end(), body.joint_lower.begin(), body.joint_lower.end());
    answer.joint_upper.insert(answer.joint_upper.end(), body.joint_upper.begin(), body.joint_upper.end());
    appendLinks(body, answer);
  }
}

}  // namespace diff_rigid_body
