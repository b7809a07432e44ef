// K configurations as one Eigen vector each (std::vector<Vector6d> or std::vector<Eigen::VectorXd>)
// for the batched calls that also take K configurations concatenated in one std::vector<double>:
// massMatrices, inverseDynamics and forwardDynamics, the same for RigidBodyClient
// (rigid_body_client.h) and RigidBodyPool (rigid_body_pool.h), so that every batched call
// (vertexJacobians, backprop too) takes the same argument type. A CRTP base: Derived has the
// overloads on std::vector<double> and says `using EigenBatches<Derived>::massMatrices;` etc.
// The dynamics also take one body at one configuration as Eigen vectors. Every overload takes the
// body or bodies first, then q and the other per-configuration values (client_earlier_orders.h
// keeps the earlier orders, deprecated).
#pragma once

#include <string>
#include <vector>

#include "diff_rigid_body_ros/client_arrays.h"
#include "diff_rigid_body_ros/client_earlier_orders.h"
#include "diff_rigid_body_ros/client_types.h"

namespace diff_rigid_body_ros
{
template <typename Derived>
class EigenBatches : public EarlierOrders<Derived>
{
public:
  using EarlierOrders<Derived>::inverseDynamics;
  using EarlierOrders<Derived>::forwardDynamics;

  /// massMatrices with qs[k] the listed bodies' x concatenated (a Vector6d for one free body).
  template <typename Vector, detail::IfEigenVector<Vector> = 0>
  MassMatrices massMatrices(const std::vector<std::string>& bodies, const std::vector<Vector>& qs,
                            bool derivatives = false)
  {
    return derived().massMatrices(bodies, detail::flatten(qs), derivatives);
  }

  /// inverseDynamics with one vector per configuration (qdots, qddots: one per configuration, or none: zeros).
  template <typename Vector, detail::IfEigenVector<Vector> = 0>
  InverseDynamicsResult inverseDynamics(const std::vector<std::string>& bodies, const std::vector<Vector>& qs,
                                        const std::vector<Vector>& qdots = {}, const std::vector<Vector>& qddots = {},
                                        bool coriolis_matrices = false, bool derivatives = false)
  {
    return derived().inverseDynamics(bodies, detail::flatten(qs), detail::flattenOptional(qdots),
                                     detail::flattenOptional(qddots), coriolis_matrices, derivatives);
  }

  /// forwardDynamics with one vector per configuration (qdots, taus: one per configuration, or none: zeros).
  template <typename Vector, detail::IfEigenVector<Vector> = 0>
  ForwardDynamicsResult forwardDynamics(const std::vector<std::string>& bodies, const std::vector<Vector>& qs,
                                        const std::vector<Vector>& qdots = {}, const std::vector<Vector>& taus = {},
                                        bool derivatives = false)
  {
    return derived().forwardDynamics(bodies, detail::flatten(qs), detail::flattenOptional(qdots),
                                     detail::flattenOptional(taus), derivatives);
  }

  /// One body at one configuration (any Eigen vectors of its d coordinates): inverseDynamics at
  /// the accelerations `xddot`, forwardDynamics under the generalised forces `tau`.
  template <typename Q, typename Qdot, typename Qddot>
  InverseDynamicsResult inverseDynamics(const std::string& body, const Eigen::MatrixBase<Q>& x,
                                        const Eigen::MatrixBase<Qdot>& xdot, const Eigen::MatrixBase<Qddot>& xddot,
                                        bool derivatives = false)
  {
    return derived().inverseDynamics({ body }, detail::values(x), detail::values(xdot), detail::values(xddot),
                                     false, derivatives);
  }
  template <typename Q, typename Qdot, typename Tau>
  ForwardDynamicsResult forwardDynamics(const std::string& body, const Eigen::MatrixBase<Q>& x,
                                        const Eigen::MatrixBase<Qdot>& xdot, const Eigen::MatrixBase<Tau>& tau,
                                        bool derivatives = false)
  {
    return derived().forwardDynamics({ body }, detail::values(x), detail::values(xdot), detail::values(tau),
                                     derivatives);
  }

private:
  Derived& derived() { return static_cast<Derived&>(*this); }
};
}  // namespace diff_rigid_body_ros
