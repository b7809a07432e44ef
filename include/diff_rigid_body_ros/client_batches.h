// K configurations as one Eigen vector each (std::vector<Vector6d> or std::vector<Eigen::VectorXd>)
// for the batched calls that also take K configurations concatenated in one std::vector<double>:
// massMatrices, inverseDynamics and forwardDynamics, the same for RigidBodyClient
// (rigid_body_client.h) and RigidBodyPool (rigid_body_pool.h), so that every batched call
// (vertexJacobians, backprop too) takes the same argument type. A CRTP base: Derived has the
// overloads on std::vector<double> and says `using EigenBatches<Derived>::massMatrices;` etc.
// The dynamics also take one body at one configuration as Eigen vectors.
#pragma once

#include <string>
#include <vector>

#include "diff_rigid_body_ros/client_arrays.h"
#include "diff_rigid_body_ros/client_types.h"

namespace diff_rigid_body_ros
{
template <typename Derived>
class EigenBatches
{
public:
  /// massMatrices with qs[k] the listed bodies' x concatenated (a Vector6d for one free body).
  template <typename Vector, detail::IfEigenVector<Vector> = 0>
  MassMatrices massMatrices(const std::vector<std::string>& bodies, const std::vector<Vector>& qs,
                            bool derivatives = false)
  {
    return derived().massMatrices(bodies, detail::flatten(qs), derivatives);
  }

  /// inverseDynamics with one vector per configuration (qdots, qddots: one per configuration, or none: zeros).
  template <typename Vector, detail::IfEigenVector<Vector> = 0>
  InverseDynamicsResult inverseDynamics(const std::vector<Vector>& qs, const std::vector<Vector>& qdots = {},
                                        const std::vector<Vector>& qddots = {},
                                        const std::vector<std::string>& bodies = {}, bool coriolis_matrices = false,
                                        bool derivatives = false)
  {
    return derived().inverseDynamics(detail::flatten(qs), detail::flattenOptional(qdots),
                                     detail::flattenOptional(qddots), bodies, coriolis_matrices, derivatives);
  }

  /// forwardDynamics with one vector per configuration (qdots, taus: one per configuration, or none: zeros).
  template <typename Vector, detail::IfEigenVector<Vector> = 0>
  ForwardDynamicsResult forwardDynamics(const std::vector<Vector>& qs, const std::vector<Vector>& qdots = {},
                                        const std::vector<Vector>& taus = {},
                                        const std::vector<std::string>& bodies = {}, bool derivatives = false)
  {
    return derived().forwardDynamics(detail::flatten(qs), detail::flattenOptional(qdots),
                                     detail::flattenOptional(taus), bodies, derivatives);
  }

  /// One body at one configuration (any Eigen vectors of its d coordinates): inverseDynamics at
  /// the accelerations `xddot`, forwardDynamics under the generalised forces `tau`.
  template <typename Q, typename Qdot, typename Qddot>
  InverseDynamicsResult inverseDynamics(const std::string& body, const Eigen::MatrixBase<Q>& x,
                                        const Eigen::MatrixBase<Qdot>& xdot, const Eigen::MatrixBase<Qddot>& xddot,
                                        bool derivatives = false)
  {
    return derived().inverseDynamics(detail::values(x), detail::values(xdot), detail::values(xddot), { body },
                                     false, derivatives);
  }
  template <typename Q, typename Qdot, typename Tau>
  ForwardDynamicsResult forwardDynamics(const std::string& body, const Eigen::MatrixBase<Q>& x,
                                        const Eigen::MatrixBase<Qdot>& xdot, const Eigen::MatrixBase<Tau>& tau,
                                        bool derivatives = false)
  {
    return derived().forwardDynamics(detail::values(x), detail::values(xdot), detail::values(tau), { body },
                                     derivatives);
  }

private:
  Derived& derived() { return static_cast<Derived&>(*this); }
};
}  // namespace diff_rigid_body_ros
