#include "diff_rigid_body/algorithm/kinematics.h"

namespace diff_rigid_body
{
template void forwardKinematics<double>(const BodyModel&, BodyWorkspace<double>&, const double*);

bool kinematicsAreFinite(const BodyModel& model, const BodyWorkspace<double>& ws)
{
  for (std::size_t s = 0; s < model.segments.size(); ++s)
    if (!ws.R[s].allFinite() || !ws.p[s].allFinite())
      return false;
  for (const Motion<double>& S : ws.S)
    if (!S.w.allFinite() || !S.v.allFinite())
      return false;
  return ws.r.allFinite();
}

void linkPoses(const BodyModel& model, BodyWorkspace<double>& ws, const double* x,
               std::vector<Eigen::Isometry3d>& poses)
{
  poses.resize(model.links.size());
  if (model.closedFormKernels())
  {
    const BodyPose<double> pose{ Eigen::Map<const Vector6<double>>(x) };
    ws.R[0] = pose.R;
    ws.p[0] = pose.t;
  }
  else
    forwardKinematics(model, ws, x);
  for (std::size_t l = 0; l < model.links.size(); ++l)
  {
    const LinkInBody& link = model.links[l];
    const Segment& segment = model.segments[link.segment];
    Eigen::Isometry3d segment_pose = Eigen::Isometry3d::Identity();
    segment_pose.linear() = ws.R[link.segment];
    segment_pose.translation() = ws.p[link.segment];
    // X_link = X_segment T(link_origin) X_segment_link: the link origin first
    // (for a free object t - R com, as version 1 placed it), then the link.
    segment_pose.translation() += segment_pose.linear() * segment.link_origin;
    poses[l] = segment_pose * link.pose_in_segment_link;
  }
}

}  // namespace diff_rigid_body
