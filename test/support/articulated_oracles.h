// Independent oracles for articulated bodies (docs/interface.md, "Version 2").
// Nothing here uses the core (kinematics.h, crba.h): the coordinates, joint limits
// and mimic map are read from the URDF (tinyxml2 for document order,
// urdfdom for the model), link poses are products of Eigen isometries and
// AngleAxis rotations, and KDL builds its own tree (kdl_parser).
//
// x = (phi, theta, psi, tx, ty, tz, j_0..j_{n-1}) for a floating root (root
// rotation Rz(psi) Ry(theta) Rx(phi), t = COM of the root link and the links
// fixed to it), else (j_0..j_{n-1}); j_k: the body's k-th independent 1-dof
// joint in URDF document order [rad, m]. A mimic joint's value is
// multiplier * x[master] + offset.
//
// Link velocities: central differences of link poses, step h along xdot:
//   v_COM = (c(x + h xdot) - c(x - h xdot)) / 2h
//   [w]x  = (R(x + h xdot) - R(x - h xdot)) / 2h R(x)^T (its antisymmetric part)
// 2T = sum over links m |v_COM|^2 + w^T (R I R^T) w = xdot^T M xdot, I about
// the COM in link axes.
#pragma once

#include <algorithm>
#include <cmath>
#include <fstream>
#include <functional>
#include <limits>
#include <map>
#include <memory>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include <Eigen/Geometry>
#include <kdl/chaindynparam.hpp>
#include <kdl/tree.hpp>
#include <kdl/treeidsolver_recursive_newton_euler.hpp>
#include <kdl_parser/kdl_parser.hpp>
#include <tinyxml2.h>
#include <urdf_parser/urdf_parser.h>

#include "oracles.h"

namespace drb_test
{
namespace articulated
{
// ---------------------------------------------------------------------------
// Coordinates from the URDF.

/// How a 1-dof joint follows x: value = multiplier * x[coordinate] + offset.
struct Drive
{
  int coordinate = -1;
  double multiplier = 1.0;
  double offset = 0.0;
};

/// The body under `root`: its links (parents first), x layout and limits.
struct BodyModel
{
  ::urdf::ModelInterfaceSharedPtr model;
  bool floating_root = false;
  std::vector<std::string> joint_names;  ///< independent joints, x order (after the root's 6)
  std::vector<double> lower, upper;      ///< -inf / +inf without <limit> (continuous)
  std::map<std::string, Drive> drives;   ///< every 1-dof joint of the body
  std::vector<::urdf::LinkConstSharedPtr> links;  ///< the root first, parents before children
  std::size_t dofs() const { return (floating_root ? 6 : 0) + joint_names.size(); }
};

inline bool isOneDof(int type)
{
  return type == ::urdf::Joint::REVOLUTE || type == ::urdf::Joint::CONTINUOUS || type == ::urdf::Joint::PRISMATIC;
}

/// Names of the <joint> children of <robot>, in document order.
inline std::vector<std::string> jointDocumentOrder(const std::string& xml)
{
  tinyxml2::XMLDocument doc;
  if (doc.Parse(xml.c_str()) != tinyxml2::XML_SUCCESS)
    throw std::runtime_error("bad XML");
  std::vector<std::string> names;
  for (const tinyxml2::XMLElement* e = doc.RootElement()->FirstChildElement("joint"); e;
       e = e->NextSiblingElement("joint"))
    names.push_back(e->Attribute("name"));
  return names;
}

inline BodyModel bodyModel(const std::string& xml, const std::string& root)
{
  BodyModel b;
  b.model = ::urdf::parseURDF(xml);
  if (!b.model)
    throw std::runtime_error("urdfdom cannot parse the description");
  const ::urdf::LinkConstSharedPtr root_link = b.model->getLink(root);
  b.floating_root = root_link->parent_joint && root_link->parent_joint->type == ::urdf::Joint::FLOATING;
  b.links.push_back(root_link);
  for (std::size_t i = 0; i < b.links.size(); ++i)
    for (const auto& joint : b.links[i]->child_joints)
      if (joint->type == ::urdf::Joint::FIXED || isOneDof(joint->type))
        b.links.push_back(b.model->getLink(joint->child_link_name));
  std::map<std::string, bool> in_body;
  for (const auto& l : b.links)
    if (l != root_link || !b.floating_root)
      in_body[l->parent_joint->name] = true;
  const int first = b.floating_root ? 6 : 0;
  for (const std::string& name : jointDocumentOrder(xml))
  {
    const ::urdf::JointConstSharedPtr j = b.model->getJoint(name);
    if (!in_body.count(name) || !isOneDof(j->type) || j->mimic)
      continue;
    b.drives[name].coordinate = first + static_cast<int>(b.joint_names.size());
    b.joint_names.push_back(name);
    const bool limited = j->type != ::urdf::Joint::CONTINUOUS && j->limits;
    b.lower.push_back(limited ? j->limits->lower : -std::numeric_limits<double>::infinity());
    b.upper.push_back(limited ? j->limits->upper : std::numeric_limits<double>::infinity());
  }
  for (const auto& [name, present] : in_body)
  {
    const ::urdf::JointConstSharedPtr j = b.model->getJoint(name);
    if (present && isOneDof(j->type) && j->mimic)
      b.drives[name] = { b.drives.at(j->mimic->joint_name).coordinate, j->mimic->multiplier, j->mimic->offset };
  }
  return b;
}

inline Eigen::Isometry3d toIsometry(const ::urdf::Pose& p)
{
  Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
  X.linear() = Eigen::Quaterniond(p.rotation.w, p.rotation.x, p.rotation.y, p.rotation.z).toRotationMatrix();
  X.translation() << p.position.x, p.position.y, p.position.z;
  return X;
}

inline Eigen::Vector3d toVector(const ::urdf::Vector3& v)
{
  return Eigen::Vector3d(v.x, v.y, v.z);
}

// ---------------------------------------------------------------------------
// Forward kinematics and the finite-difference mass matrix.

struct LinkMass
{
  double mass = 0;
  Eigen::Vector3d com = Eigen::Vector3d::Zero();      ///< link frame [m]
  Eigen::Matrix3d inertia = Eigen::Matrix3d::Zero();  ///< about the COM, link axes [kg m^2]
};

inline LinkMass linkMass(const ::urdf::Link& link)
{
  LinkMass m;
  if (!link.inertial)
    return m;
  const ::urdf::Inertial& in = *link.inertial;
  Eigen::Matrix3d I;
  I << in.ixx, in.ixy, in.ixz, in.ixy, in.iyy, in.iyz, in.ixz, in.iyz, in.izz;
  const Eigen::Isometry3d origin = toIsometry(in.origin);
  m.mass = in.mass;
  m.com = origin.translation();
  m.inertia = origin.linear() * I * origin.linear().transpose();
  return m;
}

/// Pose in the URDF root frame of every link of `b` (b.links order) at x.
inline std::vector<Eigen::Isometry3d> linkPoses(const BodyModel& b, const Eigen::VectorXd& x)
{
  std::map<std::string, Eigen::Isometry3d> pose;
  const ::urdf::LinkConstSharedPtr root = b.links.front();
  if (b.floating_root)
  {
    // The root group's COM (root link and links fixed to it, transitively) in root-link axes.
    double mass = 0;
    Eigen::Vector3d moment = Eigen::Vector3d::Zero();
    std::map<std::string, Eigen::Isometry3d> in_root{ { root->name, Eigen::Isometry3d::Identity() } };
    for (const auto& l : b.links)
      if (in_root.count(l->name))
      {
        const LinkMass m = linkMass(*l);
        mass += m.mass;
        moment += m.mass * (in_root[l->name] * m.com);
        for (const auto& j : l->child_joints)
          if (j->type == ::urdf::Joint::FIXED)
            in_root[j->child_link_name] = in_root[l->name] * toIsometry(j->parent_to_joint_origin_transform);
      }
    Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
    X.linear() = refRotation(x[0], x[1], x[2]);
    X.translation() = x.segment<3>(3) - X.linear() * (moment / mass);
    pose[root->name] = X;
  }
  else
  {
    // The static parent's pose: fixed joint origins up to the URDF root.
    Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
    for (::urdf::LinkConstSharedPtr l = b.model->getLink(root->parent_joint->parent_link_name); l->parent_joint;
         l = b.model->getLink(l->parent_joint->parent_link_name))
      X = toIsometry(l->parent_joint->parent_to_joint_origin_transform) * X;
    pose[root->parent_joint->parent_link_name] = X;
  }
  std::vector<Eigen::Isometry3d> poses;
  for (const auto& l : b.links)
  {
    if (!pose.count(l->name))
    {
      const ::urdf::Joint& j = *l->parent_joint;
      Eigen::Isometry3d motion = Eigen::Isometry3d::Identity();
      if (j.type != ::urdf::Joint::FIXED)
      {
        const Drive& d = b.drives.at(j.name);
        const double value = d.multiplier * x[d.coordinate] + d.offset;
        const Eigen::Vector3d axis = toVector(j.axis).normalized();
        if (j.type == ::urdf::Joint::PRISMATIC)
          motion.translation() = value * axis;
        else
          motion.linear() = Eigen::AngleAxisd(value, axis).toRotationMatrix();
      }
      pose[l->name] = pose.at(j.parent_link_name) * toIsometry(j.parent_to_joint_origin_transform) * motion;
    }
    poses.push_back(pose.at(l->name));
  }
  return poses;
}

/// Link COM velocity and angular velocity (fixed frame) along xdot, central differences.
struct LinkVelocities
{
  std::vector<Eigen::Vector3d> v, w;
};

inline LinkVelocities linkVelocities(const BodyModel& b, const Eigen::VectorXd& x, const Eigen::VectorXd& xdot,
                                     double h)
{
  const auto plus = linkPoses(b, x + h * xdot), minus = linkPoses(b, x - h * xdot), at = linkPoses(b, x);
  LinkVelocities out;
  for (std::size_t i = 0; i < b.links.size(); ++i)
  {
    const Eigen::Vector3d com = linkMass(*b.links[i]).com;
    out.v.push_back((plus[i] * com - minus[i] * com) / (2 * h));
    const Eigen::Matrix3d Rdot = (plus[i].linear() - minus[i].linear()) / (2 * h);
    out.w.push_back(vee(Eigen::Matrix3d(Rdot * at[i].linear().transpose())));
  }
  return out;
}

/// 2T = sum m |v|^2 + w^T R I R^T w, link velocities by central differences.
inline double twiceKineticEnergy(const BodyModel& b, const Eigen::VectorXd& x, const Eigen::VectorXd& xdot, double h)
{
  const LinkVelocities vel = linkVelocities(b, x, xdot, h);
  const auto at = linkPoses(b, x);
  double e = 0;
  for (std::size_t i = 0; i < b.links.size(); ++i)
  {
    const LinkMass m = linkMass(*b.links[i]);
    const Eigen::Matrix3d I = at[i].linear() * m.inertia * at[i].linear().transpose();
    e += m.mass * vel.v[i].squaredNorm() + vel.w[i].dot(I * vel.w[i]);
  }
  return e;
}

/// M by polarisation of 2T: M_ii = 2T(e_i), M_ij = (2T(e_i + e_j) - 2T(e_i) - 2T(e_j)) / 2.
inline Eigen::MatrixXd finiteDifferenceMassMatrix(const BodyModel& b, const Eigen::VectorXd& x, double h)
{
  const Eigen::Index n = static_cast<Eigen::Index>(b.dofs());
  Eigen::MatrixXd M(n, n);
  for (Eigen::Index i = 0; i < n; ++i)
    M(i, i) = twiceKineticEnergy(b, x, Eigen::VectorXd::Unit(n, i), h);
  for (Eigen::Index i = 0; i < n; ++i)
    for (Eigen::Index j = i + 1; j < n; ++j)
      M(i, j) = M(j, i) =
          (twiceKineticEnergy(b, x, Eigen::VectorXd::Unit(n, i) + Eigen::VectorXd::Unit(n, j), h) - M(i, i) - M(j, j)) / 2;
  return M;
}

// ---------------------------------------------------------------------------
// KDL: the tree of kdl_parser, one KDL joint per 1-dof URDF joint (mimic
// joints are independent there). q_kdl = P x + offset, so M = P^T M_kdl P.

class KdlOracle
{
public:
  explicit KdlOracle(const BodyModel& b) : body_(b)
  {
    if (!kdl_parser::treeFromUrdfModel(*b.model, tree_))
      throw std::runtime_error("kdl_parser failed");
    const Eigen::Index n = tree_.getNrOfJoints();
    P_ = Eigen::MatrixXd::Zero(n, static_cast<Eigen::Index>(b.dofs()));
    offset_ = Eigen::VectorXd::Zero(n);
    for (const auto& [name, element] : tree_.getSegments())
    {
      const KDL::Joint& joint = GetTreeElementSegment(element).getJoint();
      if (joint.getType() == KDL::Joint::None || !b.drives.count(joint.getName()))
        continue;
      const Drive& d = b.drives.at(joint.getName());
      P_(GetTreeElementQNr(element), d.coordinate) = d.multiplier;
      offset_[GetTreeElementQNr(element)] = d.offset;
    }
  }

  /// Columns of the whole tree's joint-space inertia by RNE: qdd = e_i, qdot = 0, g = 0.
  Eigen::MatrixXd massMatrix(const Eigen::VectorXd& x) const
  {
    const unsigned n = tree_.getNrOfJoints();
    KDL::JntArray q(n), zero(n), qdd(n), tau(n);
    q.data = P_ * x + offset_;
    KDL::TreeIdSolver_RNE solver(tree_, KDL::Vector::Zero());
    Eigen::MatrixXd M_full(n, n);
    for (unsigned i = 0; i < n; ++i)
    {
      qdd.data.setZero();
      qdd(i) = 1.0;
      if (solver.CartToJnt(q, zero, qdd, KDL::WrenchMap(), tau) < 0)
        throw std::runtime_error("TreeIdSolver_RNE failed");
      M_full.col(i) = tau.data;
    }
    return P_.transpose() * M_full * P_;
  }

  /// ChainDynParam::JntToMass on the chain root..tip, in x order (every
  /// chain joint must be an independent coordinate); `chain_mass` gets the
  /// chain's total mass.
  Eigen::MatrixXd chainMassMatrix(const std::string& root, const std::string& tip, const Eigen::VectorXd& x,
                                  double* chain_mass) const
  {
    KDL::Chain chain;
    if (!tree_.getChain(root, tip, chain))
      throw std::runtime_error("no chain " + root + ".." + tip);
    KDL::JntArray q(chain.getNrOfJoints());
    std::vector<int> coordinate;
    *chain_mass = 0;
    for (const KDL::Segment& s : chain.segments)
    {
      *chain_mass += s.getInertia().getMass();
      if (s.getJoint().getType() == KDL::Joint::None)
        continue;
      const Drive& d = body_.drives.at(s.getJoint().getName());
      q(coordinate.size()) = x[d.coordinate];
      coordinate.push_back(d.coordinate);
    }
    KDL::JntSpaceInertiaMatrix H(chain.getNrOfJoints());
    KDL::ChainDynParam(chain, KDL::Vector::Zero()).JntToMass(q, H);
    Eigen::MatrixXd M = Eigen::MatrixXd::Zero(x.size(), x.size());
    for (std::size_t i = 0; i < coordinate.size(); ++i)
      for (std::size_t j = 0; j < coordinate.size(); ++j)
        M(coordinate[i], coordinate[j]) = H(i, j);
    return M;
  }

private:
  const BodyModel& body_;
  KDL::Tree tree_;
  Eigen::MatrixXd P_;
  Eigen::VectorXd offset_;
};

}  // namespace articulated
}  // namespace drb_test
