// What diff_rigid_body_ros::RigidBodyClient (rigid_body_client.h) returns and
// throws. Eigen types; no ROS header.
//
// A body's coordinates x have d = dof values (get_bodies' dofs): a free
// body's x is q = (phi, theta, psi [rad], tx, ty, tz [m]), d = 6; an
// articulated body's x is its floating root's q (if it floats) followed by
// its joint positions [rad or m] (docs/interface.md, "Version 2"). Matrices are
// in x order.
#pragma once

#include <cstdint>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>

namespace diff_rigid_body_ros
{
using Vector6d = Eigen::Matrix<double, 6, 1>;
using Matrix6d = Eigen::Matrix<double, 6, 6>;
/// Stacked vertex Jacobians: rows 3v..3v+2 are J_v = dp_v/dx (3 x d).
using StackedJacobians = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

/// A service answered success=false. message() is the node's explanation
/// (it names the body, index or field); the node's state is unchanged.
class ServiceError : public std::runtime_error
{
public:
  ServiceError(const std::string& service, const std::string& message)
    : std::runtime_error(service + ": " + message), service_(service), message_(message)
  {
  }
  const std::string& service() const { return service_; }
  const std::string& message() const { return message_; }

private:
  std::string service_;
  std::string message_;
};

/// A service could not be reached (not advertised within the timeout, or the
/// call failed again after reconnecting).
class ConnectionError : public std::runtime_error
{
public:
  using std::runtime_error::runtime_error;
};

/// One link of a body (get_bodies), in vertex order.
struct Link
{
  std::string name;
  double mass = 0.0;                                  ///< [kg], 0 for a massless frame
  Eigen::Matrix3d inertia = Eigen::Matrix3d::Zero();  ///< [kg m^2] about its COM, link axes
  Eigen::Vector3d com_offset = Eigen::Vector3d::Zero();  ///< [m] its COM in its frame
  std::uint32_t first_vertex = 0;  ///< its vertices: first_vertex .. first_vertex + vertex_count - 1
  std::uint32_t vertex_count = 0;
};

/// get_bodies.
struct Bodies
{
  std::string fixed_frame;
  std::vector<std::string> names;
  std::vector<double> masses;                     ///< [kg], the total of the body's links
  std::vector<Eigen::Matrix3d> inertias;          ///< [kg m^2] about the (root link's) COM, body axes
  std::vector<Eigen::Vector3d> com_offsets;       ///< [m] the (root link's) COM in its link frame
  std::vector<std::uint32_t> vertex_counts;
  std::vector<std::uint32_t> dofs;                ///< d = len(x) per body
  std::vector<std::vector<std::string>> joint_names;  ///< per body, the joints of x in x order
  std::vector<std::vector<double>> joint_lower;   ///< per body and joint [rad or m], -inf where none
  std::vector<std::vector<double>> joint_upper;   ///< per body and joint [rad or m], +inf where none
  std::vector<std::vector<Link>> links;           ///< per body, in vertex order
};

/// get_mass_matrix: K configurations of n bodies; body i's matrices are d_i x d_i.
struct MassMatrices
{
  std::vector<std::string> bodies;             ///< the n bodies, in answer order
  std::vector<std::uint32_t> dofs;             ///< d_i per body
  std::size_t configurations = 0;              ///< K
  std::vector<Eigen::MatrixXd> M;              ///< K*n matrices; configuration k, body i at k*n + i
  std::vector<std::vector<Eigen::MatrixXd>> dM;  ///< with derivatives: dM[k*n + i][j] = dM/dx_j
  std::vector<double> cos_theta;               ///< gimbal-lock diagnostic, one per matrix (1 for a fixed base)

  const Eigen::MatrixXd& at(std::size_t k, std::size_t i) const { return M.at(k * bodies.size() + i); }
};

/// inverse_dynamics: K configurations of n bodies; entry m = k*n + i is body i at configuration
/// k (index(k, i)): d_i values per vector, d_i x d_i matrices (row = tau component).
struct InverseDynamicsResult
{
  std::vector<std::string> bodies;                 ///< the n bodies, in answer order
  std::vector<std::uint32_t> dofs;                 ///< d_i per body
  std::size_t configurations = 0;                  ///< K
  std::vector<Eigen::VectorXd> tau;                ///< M x'' + c + g [N m, N]
  std::vector<Eigen::VectorXd> velocity_terms;     ///< c = C x'
  std::vector<Eigen::VectorXd> gravity_terms;      ///< g = dV/dx (~gravity)
  std::vector<Eigen::MatrixXd> coriolis_matrices;  ///< C, when asked (else empty)
  std::vector<Eigen::MatrixXd> dtau_dq;            ///< dtau/dx, with derivatives (else empty)
  std::vector<Eigen::MatrixXd> dtau_dqdot;         ///< dtau/dx' = 2 C, with derivatives (else empty)
  std::vector<double> cos_theta;                   ///< gimbal-lock diagnostic per entry (1 for a fixed base)

  std::size_t index(std::size_t k, std::size_t i) const { return k * bodies.size() + i; }
};

/// forward_dynamics, laid out as InverseDynamicsResult (row = x'' component).
struct ForwardDynamicsResult
{
  std::vector<std::string> bodies;
  std::vector<std::uint32_t> dofs;
  std::size_t configurations = 0;
  std::vector<Eigen::VectorXd> qddot;         ///< x'' = M^-1 (tau - c - g) [rad/s^2, m/s^2]
  std::vector<Eigen::MatrixXd> dqddot_dq;     ///< dx''/dx, with derivatives (else empty)
  std::vector<Eigen::MatrixXd> dqddot_dqdot;  ///< dx''/dx', with derivatives (else empty)
  std::vector<Eigen::MatrixXd> dqddot_dtau;   ///< dx''/dtau = M^-1, with derivatives (else empty)
  std::vector<double> cos_theta;

  std::size_t index(std::size_t k, std::size_t i) const { return k * bodies.size() + i; }
};

/// get_vertex_jacobians.
struct VertexJacobians
{
  Eigen::Matrix3Xd positions;  ///< [m] column v = vertex v in the fixed frame
  StackedJacobians J;          ///< 3N x d; J.middleRows<3>(3 * v) = dp_v/dx

  Eigen::Matrix<double, 3, Eigen::Dynamic> jacobian(Eigen::Index v) const { return J.middleRows<3>(3 * v); }
};

/// get_vertex_jacobians_compact, in Scalar = double or float (the float32
/// transport: the double values rounded to float32). The columns that are
/// always I3 are not sent: a free body's J_v = [ Jr_v | I3 ] comes as the
/// rotation block Jr_v = dp_v/d(phi, theta, psi) (3 columns); a floating
/// root with joints: every column but tx, ty, tz (d - 3); a fixed base: all d.
template <typename Scalar>
struct VertexRotationJacobians
{
  using StackedRotationJacobians = Eigen::Matrix<Scalar, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
  Eigen::Matrix<Scalar, 3, Eigen::Dynamic> positions;  ///< [m] column v = vertex v in the fixed frame
  StackedRotationJacobians Jr;  ///< 3N x c; Jr.middleRows<3>(3 * v) = Jr_v; 0 x c with positions_only

  Eigen::Matrix<Scalar, 3, Eigen::Dynamic> rotationJacobian(Eigen::Index v) const
  {
    return Jr.template middleRows<3>(3 * v);
  }
};

/// get_state: (name, x) pairs. Converts to (name, Vector6d) pairs when every
/// body has 6 coordinates (throws std::length_error otherwise).
class BodyStates : public std::vector<std::pair<std::string, Eigen::VectorXd>>
{
public:
  operator std::vector<std::pair<std::string, Vector6d>>() const
  {
    std::vector<std::pair<std::string, Vector6d>> out;
    for (const auto& state : *this)
    {
      if (state.second.size() != 6)
        throw std::length_error("get_state: body '" + state.first + "' has " + std::to_string(state.second.size()) +
                                " coordinates, not 6");
      out.emplace_back(state.first, state.second);
    }
    return out;
  }
};

}  // namespace diff_rigid_body_ros
