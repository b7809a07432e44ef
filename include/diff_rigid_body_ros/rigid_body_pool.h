// A pool of rigid_body_server instances serving the same scene, used as one client: the C++
// counterpart of diff_rigid_body.RigidBodyPool (src/diff_rigid_body/pool.py).
//
// A call of K > 1 configurations to massMatrices, inverseDynamics, forwardDynamics,
// vertexJacobians, backprop, frameJacobians, centerOfMass (or to query<Srv>, a generated method of
// client_declared.h, or call() with any service of pool_shards.h) is cut into contiguous
// shards, one per live instance, sent concurrently (one worker thread per instance) and joined in
// configuration order: the answer has the bits of one instance's answer.
//  - Same scene: the constructor asks every instance for get_bodies and throws PoolError for an
//    instance whose bodies, dofs, masses, inertias, joints or vertex counts differ from the first's.
//  - Failover: an instance whose call fails (ConnectionError: the node died) or that gives no
//    answer within call_timeout is logged by name and marked down; its shard is cut again over the
//    live instances. With none left: PoolError naming every instance. A ServiceError (the node
//    refused the request) is the answer: it is thrown at once.
//  - Recovery: a down instance is asked again (by its worker, at most every retry_interval) and
//    rejoins once it answers with the same scene.
//  - Shard sizes follow each instance's measured throughput per service, so a slower host gets less.
// A request without q (the node's current state) or of one configuration goes whole to one live
// instance. Not thread-safe: one pool per thread. roscpp has no call timeout: a worker whose
// instance hangs stays in that call (the instance stays out) until the connection drops.
#pragma once

#include <algorithm>
#include <chrono>
#include <deque>
#include <exception>
#include <functional>
#include <map>
#include <memory>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include <ros/ros.h>

#include "diff_rigid_body_ros/client_batches.h"
#include "diff_rigid_body_ros/client_declared.h"
#include "diff_rigid_body_ros/client_frames.h"
#include "diff_rigid_body_ros/client_requests.h"
#include "diff_rigid_body_ros/client_responses.h"
#include "diff_rigid_body_ros/pool_shards.h"
#include "diff_rigid_body_ros/pool_instances.h"
#include "diff_rigid_body_ros/rigid_body_client.h"

namespace diff_rigid_body_ros
{
class RigidBodyPool : public EigenBatches<RigidBodyPool>, public DeclaredQueries<RigidBodyPool>
{
public:
  /// `namespaces`: the instances, each a namespace, e.g. {"/pool1", "/pool2"} (node
  /// <ns>/<options.server>), or a node name, e.g. "/pool1/rigid_body_server" (an entry whose last
  /// name is options.server), resolved in nh's namespace; the same node twice opens two connections.
  explicit RigidBodyPool(const std::vector<std::string>& namespaces, PoolOptions options = PoolOptions(),
                         const ros::NodeHandle& nh = ros::NodeHandle())
    : shared_(std::make_shared<pool::Shared>())
  {
    if (namespaces.empty())
      throw std::invalid_argument("RigidBodyPool: at least one namespace or node name");
    if (!options.log)
      options.log = [](const std::string& text) { ROS_WARN_STREAM(text); };
    shared_->options = std::move(options);
    for (const std::string& entry : namespaces)
      instances_.push_back(std::make_shared<pool::Instance>(nh, detail::poolNodeName(entry, shared_->options.server),
                                                            ros::Duration(shared_->options.probe_timeout)));
    checkScenes();
  }

  /// The scene every instance serves (get_bodies of the first).
  const Bodies& bodies() const { return bodies_; }

  /// As RigidBodyClient::massMatrices, sharded over the instances.
  MassMatrices massMatrices(const std::vector<std::string>& bodies, const std::vector<double>& q,
                            bool derivatives = false)
  {
    auto srv = detail::requestOf<diff_rigid_body::GetMassMatrix>(bodies, q, derivatives);
    call(srv);
    return toMassMatrices(srv.response, derivatives);
  }
  using EigenBatches<RigidBodyPool>::massMatrices;  // K configurations as std::vector<Vector6d or VectorXd>
  /// As RigidBodyClient::inverseDynamics (flat q, or one Eigen vector per configuration).
  InverseDynamicsResult inverseDynamics(const std::vector<std::string>& bodies, const std::vector<double>& q,
                                        const std::vector<double>& qdot = {}, const std::vector<double>& qddot = {},
                                        bool coriolis_matrices = false, bool derivatives = false)
  {
    auto srv = detail::requestOf<diff_rigid_body::InverseDynamics>(bodies, q, qdot, qddot, coriolis_matrices,
                                                                   derivatives);
    call(srv);
    return toInverseDynamics(srv.response);
  }
  using EigenBatches<RigidBodyPool>::inverseDynamics;
  /// As RigidBodyClient::forwardDynamics (flat q, or one Eigen vector per configuration).
  ForwardDynamicsResult forwardDynamics(const std::vector<std::string>& bodies, const std::vector<double>& q,
                                        const std::vector<double>& qdot = {}, const std::vector<double>& tau = {},
                                        bool derivatives = false)
  {
    auto srv = detail::requestOf<diff_rigid_body::ForwardDynamics>(bodies, q, qdot, tau, derivatives);
    call(srv);
    return toForwardDynamics(srv.response);
  }
  using EigenBatches<RigidBodyPool>::forwardDynamics;
  /// As RigidBodyClient::frameJacobians and centerOfMass, sharded over the instances.
  FrameJacobians frameJacobians(const std::string& body, const std::vector<double>& q,
                                const std::vector<double>& qdot = {}, const std::vector<std::string>& frames = {},
                                FrameReference reference = FrameReference::LocalWorldAligned,
                                bool acceleration_bias = false)
  {
    auto srv = detail::requestOf<diff_rigid_body::GetFrameJacobians>(
        body, frames, q, qdot, static_cast<std::uint8_t>(reference), acceleration_bias);
    call(srv);
    return toFrameJacobians(srv.response);
  }
  using EigenBatches<RigidBodyPool>::frameJacobians;  // the earlier order (client_earlier_orders.h)
  CenterOfMassResult centerOfMass(const std::vector<std::string>& bodies, const std::vector<double>& q,
                                  const std::vector<double>& qdot = {}, bool jacobians = false)
  {
    auto srv = detail::requestOf<diff_rigid_body::GetCenterOfMass>(bodies, q, qdot, jacobians);
    call(srv);
    return toCenterOfMass(srv.response);
  }

  /// As RigidBodyClient::vertexJacobians with K configurations: block k for qs[k] (Vector6d or VectorXd).
  std::vector<VertexJacobians> vertexJacobians(const std::string& body, const std::vector<Eigen::VectorXd>& qs,
                                               const std::vector<std::uint32_t>& vertices = {})
  {
    return vertexJacobians<Eigen::VectorXd>(body, qs, vertices);
  }
  template <typename Vector, detail::IfEigenVector<Vector> = 0>
  std::vector<VertexJacobians> vertexJacobians(const std::string& body, const std::vector<Vector>& qs,
                                               const std::vector<std::uint32_t>& vertices = {})
  {
    auto srv = detail::requestOf<diff_rigid_body::GetVertexJacobians>(body, vertices, detail::flatten(qs));
    call(srv);
    return toVertexJacobians(srv.response, qs.size());
  }
  /// As RigidBodyClient::backprop with K configurations: dL/dx at qs[k] from dL_dp[k] (3 x N), as qs' type.
  std::vector<Eigen::VectorXd> backprop(const std::string& body, const std::vector<Eigen::Matrix3Xd>& dL_dp,
                                        const std::vector<Eigen::VectorXd>& qs,
                                        const std::vector<std::uint32_t>& vertices = {})
  {
    return backprop<Eigen::VectorXd>(body, dL_dp, qs, vertices);
  }
  template <typename Vector, detail::IfEigenVector<Vector> = 0>
  std::vector<Vector> backprop(const std::string& body, const std::vector<Eigen::Matrix3Xd>& dL_dp,
                               const std::vector<Vector>& qs, const std::vector<std::uint32_t>& vertices = {})
  {
    if (dL_dp.size() != qs.size())
      throw std::invalid_argument("backprop: " + std::to_string(dL_dp.size()) + " gradient blocks for " +
                                  std::to_string(qs.size()) + " configurations");
    auto srv = detail::requestOf<diff_rigid_body::Backprop>(body, vertices, detail::flattenGradients(dL_dp),
                                                            detail::flatten(qs));
    call(srv);
    const std::vector<Eigen::VectorXd> out = toGradients(srv.response, qs.size());
    return std::vector<Vector>(out.begin(), out.end());
  }

  /// Any sharded service (pool_shards.h: Sharding<Service>): srv.response is the joined answer.
  template <typename Service>
  void call(Service& srv)
  {
    static_assert(pool::IsSharded<Service>::value,
                  "RigidBodyPool answers the K-configuration services (DRB_SHARDED_SERVICES); "
                  "get_bodies is bodies(), and a service without configurations goes to one RigidBodyClient");
    probeDownInstances();
    const std::size_t K = pool::configurationCount<Service>(srv.request, dofs_);
    std::deque<std::pair<std::size_t, std::size_t>> pending{ { 0, K } };  // K = 0: the whole request
    std::map<std::size_t, typename Service::Response> answers;            // by first configuration
    while (!pending.empty())
    {
      const std::vector<std::shared_ptr<pool::Instance>> live = liveInstances();
      if (live.empty())
        throw allDown(std::string(pool::Sharding<Service>::service) + " failed");
      const auto range = pending.front();  // one range per round: an instance has one call in flight
      pending.pop_front();
      for (const auto& again : runRound<Service>(srv.request, K, range.first, range.second, live, answers))
        pending.push_back(again);
    }
    srv.response = std::move(answers.begin()->second);
    for (auto shard = std::next(answers.begin()); shard != answers.end(); ++shard)
      pool::appendResponse<Service>(srv.response, shard->second);
  }

  std::vector<InstanceStatus> status() const
  {
    std::vector<InstanceStatus> out;
    for (const auto& instance : instances_)
    {
      std::lock_guard<std::mutex> lock(instance->mutex);
      out.push_back({ instance->server, instance->up, instance->up ? "" : instance->failure, instance->rates });
    }
    return out;
  }

private:
  /// get_bodies of every instance, concurrently (each worker waits up to options.timeout for its
  /// service); the first answer is the scene. Unreachable instances start down; one serving another
  /// scene throws PoolError.
  void checkScenes()
  {
    const pool::SceneAnswers answers = pool::askScenes(instances_, shared_->options.timeout);
    const std::deque<bool>& finished = answers.finished;
    const auto& round = answers.round;
    bool have_scene = false;
    for (std::size_t i = 0; i < instances_.size(); ++i)
    {
      if (!finished[i] || round->pieces[i].second)
      {
        pool::markDown(*instances_[i], finished[i] ? pool::describe(round->pieces[i].second) : "no answer", *shared_);
        continue;
      }
      const auto& answer = round->pieces[i].first.response;
      if (!have_scene)
        shared_->scene = answer;
      have_scene = true;
      const std::string differs = pool::sceneMismatch(shared_->scene, answer);
      if (!differs.empty())
        throw PoolError(instances_[i]->server + " serves another scene than the first instance (" + differs +
                            " differ)",
                        { { instances_[i]->server, differs + " differ" } });
      instances_[i]->up = true;
    }
    if (!have_scene)
      throw allDown("no instance answered get_bodies");
    bodies_ = toBodies(shared_->scene);
    dofs_.order = shared_->scene.names;
    for (std::size_t i = 0; i < shared_->scene.names.size(); ++i)
      dofs_.by_name[shared_->scene.names[i]] = shared_->scene.dofs[i];
  }

  std::vector<std::shared_ptr<pool::Instance>> liveInstances() const
  {
    std::vector<std::shared_ptr<pool::Instance>> live;
    for (const auto& instance : instances_)
      if (instance->up && !instance->busy)
        live.push_back(instance);
    return live;
  }

  PoolError allDown(const std::string& what) const
  {
    std::map<std::string, std::string> failures;
    std::string text = "RigidBodyPool: " + what + "; every instance is down:";
    for (const auto& instance : instances_)
    {
      std::lock_guard<std::mutex> lock(instance->mutex);
      failures[instance->server] = instance->failure;
      text += " " + instance->server + ": " + instance->failure + ";";
    }
    return PoolError(text, failures);
  }

  /// Down instances whose retry time has come are probed by their workers; the call does not wait.
  void probeDownInstances()
  {
    const auto now = std::chrono::steady_clock::now();
    for (const auto& instance : instances_)
    {
      std::unique_lock<std::mutex> lock(instance->mutex);
      if (instance->up || instance->busy || now < instance->retry_at)
        continue;
      lock.unlock();
      instance->busy = true;
      instance->worker.submit(
          [instance, shared = std::shared_ptr<const pool::Shared>(shared_)] { pool::probe(instance, shared); });
    }
  }

  template <typename Service>
  struct Piece
  {
    std::shared_ptr<pool::Instance> instance;
    std::size_t start = 0, stop = 0;  ///< configurations [start, stop) of the call; 0, 0: the whole request
    Service srv;
    std::exception_ptr error;
    double seconds = 0.0;
  };

  /// Configurations [start, stop) of the request (the whole request when K = 0) over the live
  /// instances by throughput, sent concurrently. Answers go to `answers` by first configuration;
  /// returns the ranges to send again (their instance failed or timed out).
  template <typename Service>
  std::vector<std::pair<std::size_t, std::size_t>> runRound(
      typename Service::Request& request, std::size_t K, std::size_t start, std::size_t stop,
      const std::vector<std::shared_ptr<pool::Instance>>& live,
      std::map<std::size_t, typename Service::Response>& answers)
  {
    const std::string service = pool::Sharding<Service>::service;
    auto round = std::make_shared<pool::Round<Piece<Service>>>();
    cut<Service>(request, K, start, stop, live, *round);
    for (std::size_t i = 0; i < round->pieces.size(); ++i)
    {
      round->pieces[i].instance->busy = true;
      round->pieces[i].instance->worker.submit([round, i, service] {
        Piece<Service>& piece = round->pieces[i];
        const auto begin = std::chrono::steady_clock::now();
        try
        {
          piece.instance->client.call(service, piece.srv);
        }
        catch (...)
        {
          piece.error = std::current_exception();
        }
        piece.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - begin).count();
        piece.instance->busy = false;
        round->finish(i);
      });
    }
    const std::deque<bool> finished = round->wait(std::chrono::duration<double>(shared_->options.call_timeout));
    std::vector<std::pair<std::size_t, std::size_t>> again;
    for (std::size_t i = 0; i < round->pieces.size(); ++i)
    {
      Piece<Service>& piece = round->pieces[i];
      if (!finished[i])
        pool::markDown(*piece.instance, "no answer within " + std::to_string(shared_->options.call_timeout) + " s",
                       *shared_);
      else if (piece.error)
        classify<Service>(piece, K);
      else
      {
        piece.instance->record(service, K ? piece.stop - piece.start : 1, piece.seconds,
                               shared_->options.rate_smoothing);
        answers[piece.start] = std::move(piece.srv.response);
        continue;
      }
      again.emplace_back(piece.start, piece.stop);
    }
    return again;
  }

  /// The pieces of one round: the whole request to the fastest live instance (K = 0), or
  /// [start, stop) cut in proportion to the instances' measured rates (unknown: their mean).
  template <typename Service>
  void cut(typename Service::Request& request, std::size_t K, std::size_t start, std::size_t stop,
           const std::vector<std::shared_ptr<pool::Instance>>& live, pool::Round<Piece<Service>>& round)
  {
    const std::string service = pool::Sharding<Service>::service;
    std::vector<double> rates;
    double known = 0.0, count = 0.0;
    for (const auto& instance : live)
    {
      std::lock_guard<std::mutex> lock(instance->mutex);
      const auto found = instance->rates.find(service);
      rates.push_back(found == instance->rates.end() ? 0.0 : found->second);
      known += rates.back(), count += rates.back() > 0.0;
    }
    for (double& rate : rates)
      rate = rate > 0.0 ? rate : (count > 0.0 ? known / count : 1.0);
    const std::vector<std::size_t> counts =
        K ? pool::apportion(stop - start, rates) : std::vector<std::size_t>{ 1 };
    const std::size_t fastest = std::max_element(rates.begin(), rates.end()) - rates.begin();
    for (std::size_t i = 0; i < counts.size(); ++i)
    {
      if (counts[i] == 0)
        continue;
      Piece<Service> piece;
      piece.instance = K ? live[i] : live[fastest];
      piece.start = start;
      piece.stop = K ? start + counts[i] : 0;
      piece.srv.request = K ? pool::shardRequest<Service>(request, K, start, piece.stop) : request;
      start = piece.stop;
      round.pieces.push_back(std::move(piece));
      round.finished.push_back(false);
    }
  }

  /// A failed piece: ConnectionError marks its instance down (the range is sent again); a refusal
  /// (ServiceError) or anything else is thrown, a refusal of a shard naming its configurations.
  template <typename Service>
  void classify(const Piece<Service>& piece, std::size_t K)
  {
    try
    {
      std::rethrow_exception(piece.error);
    }
    catch (const ConnectionError& e)
    {
      pool::markDown(*piece.instance, e.what(), *shared_);
    }
    catch (const ServiceError& e)
    {
      if (K == 0 || (piece.start == 0 && piece.stop == K))
        throw;
      throw ServiceError(e.service(), e.message() + " (pool: configurations " + std::to_string(piece.start) + ".." +
                                          std::to_string(piece.stop - 1) + " of the call, sent to " +
                                          piece.instance->server + " as its configurations 0.." +
                                          std::to_string(piece.stop - piece.start - 1) + ")");
    }
  }

  std::shared_ptr<pool::Shared> shared_;
  std::vector<std::shared_ptr<pool::Instance>> instances_;
  pool::SceneDofs dofs_;
  Bodies bodies_;
};

}  // namespace diff_rigid_body_ros
