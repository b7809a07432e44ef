// diff_rigid_body_ros::RigidBodyPool (pool_cpp.test): two instances of the Panda started by
// launch/pool.launch as separate processes advertising 127.0.0.2 and 127.0.0.3, and one of the
// default scene (/other). Oracles: one instance's own answer through RigidBodyClient (bit for bit),
// the node's absence (a pool over namespaces nobody serves), another scene's get_bodies. The last
// test freezes /pool2 (SIGSTOP), starts a call, kills /pool2 (SIGKILL) while the call waits on it,
// and requires the same answer, no exception and /pool2 logged as down.
#include <signal.h>

#include <chrono>
#include <cmath>
#include <cstring>
#include <string>
#include <thread>
#include <vector>

#include <Eigen/Core>
#include <gtest/gtest.h>
#include <ros/network.h>
#include <ros/ros.h>
#include <xmlrpcpp/XmlRpc.h>

#include "diff_rigid_body_ros/rigid_body_pool.h"
#include "../support/expect_throws.h"

namespace
{
namespace drb = diff_rigid_body_ros;

const std::vector<std::string> kPool = { "/pool1", "/pool2" };
const std::string kBody = "panda_link1";

// K configurations of the Panda's 8 coordinates, spread over its joint range.
std::vector<Eigen::VectorXd> configurations(std::size_t K)
{
  std::vector<Eigen::VectorXd> qs;
  for (std::size_t k = 0; k < K; ++k)
  {
    Eigen::VectorXd q(8);
    for (Eigen::Index j = 0; j < 8; ++j)
      q[j] = 0.9 * std::sin(0.37 * static_cast<double>(k) + 1.1 * static_cast<double>(j));
    q[7] = 0.02;  // a finger: prismatic [m]
    qs.push_back(q);
  }
  return qs;
}

std::vector<double> flat(const std::vector<Eigen::VectorXd>& qs, double scale = 1.0)
{
  std::vector<double> out;
  for (const Eigen::VectorXd& q : qs)
    for (Eigen::Index j = 0; j < q.size(); ++j)
      out.push_back(scale * q[j]);
  return out;
}

std::vector<Eigen::Matrix3Xd> gradients(std::size_t K, Eigen::Index N)
{
  std::vector<Eigen::Matrix3Xd> out;
  for (std::size_t k = 0; k < K; ++k)
  {
    Eigen::Matrix3Xd g(3, N);
    for (Eigen::Index i = 0; i < g.size(); ++i)
      g.data()[i] = std::sin(0.7 * static_cast<double>(i) + 1.3 * static_cast<double>(k));
    out.push_back(g);
  }
  return out;
}

template <typename Matrix>
void expectSameBits(const std::vector<Matrix>& pool, const std::vector<Matrix>& one, const std::string& what)
{
  ASSERT_EQ(pool.size(), one.size()) << what;
  for (std::size_t i = 0; i < pool.size(); ++i)
  {
    ASSERT_EQ(pool[i].rows(), one[i].rows()) << what << " [" << i << "]";
    ASSERT_EQ(pool[i].cols(), one[i].cols()) << what << " [" << i << "]";
    EXPECT_EQ(0, std::memcmp(pool[i].data(), one[i].data(), sizeof(double) * one[i].size())) << what << " [" << i
                                                                                              << "]";
  }
}

// The process id of a node, from its XML-RPC getPid.
int nodePid(const std::string& node)
{
  XmlRpc::XmlRpcValue args, result, payload;
  args[0] = ros::this_node::getName();
  args[1] = node;
  if (!ros::master::execute("lookupNode", args, result, payload, true))
    return -1;
  std::string uri = payload, host;
  std::uint32_t port = 0;
  if (!ros::network::splitURI(uri, host, port))
    return -1;
  XmlRpc::XmlRpcClient client(host.c_str(), static_cast<int>(port), "/");
  XmlRpc::XmlRpcValue pid_args, pid_result;
  pid_args[0] = ros::this_node::getName();
  if (!client.execute("getPid", pid_args, pid_result))
    return -1;
  return static_cast<int>(pid_result[2]);
}

drb::PoolOptions quietOptions(std::vector<std::string>* log)
{
  drb::PoolOptions options;
  options.timeout = 60.0;
  options.log = [log](const std::string& text) { log->push_back(text); };
  return options;
}

TEST(RigidBodyPool, AnswersEqualOneInstanceBitForBit)
{
  std::vector<std::string> log;
  drb::RigidBodyPool pool(kPool, quietOptions(&log));
  drb::RigidBodyClient one(ros::NodeHandle(), "/pool1/rigid_body_server", ros::Duration(60.0));
  for (std::size_t K : { 1, 2, 7, 100 })
  {
    const auto qs = configurations(K);
    const std::string where = " K = " + std::to_string(K);
    const auto M = pool.massMatrices({}, flat(qs), true), M1 = one.massMatrices({}, flat(qs), true);
    expectSameBits(M.M, M1.M, "M" + where);
    for (std::size_t m = 0; m < M1.dM.size(); ++m)
      expectSameBits(M.dM.at(m), M1.dM[m], "dM" + where);
    const auto id = pool.inverseDynamics({}, flat(qs), flat(qs, 0.5), flat(qs, -0.3), true, true);
    const auto id1 = one.inverseDynamics({}, flat(qs), flat(qs, 0.5), flat(qs, -0.3), true, true);
    expectSameBits(id.tau, id1.tau, "tau" + where);
    expectSameBits(id.coriolis_matrices, id1.coriolis_matrices, "C" + where);
    expectSameBits(id.dtau_dq, id1.dtau_dq, "dtau_dq" + where);
    const auto fd = pool.forwardDynamics({}, flat(qs), flat(qs, 0.5), flat(qs, 2.0), true);
    const auto fd1 = one.forwardDynamics({}, flat(qs), flat(qs, 0.5), flat(qs, 2.0), true);
    expectSameBits(fd.qddot, fd1.qddot, "qddot" + where);
    expectSameBits(fd.dqddot_dtau, fd1.dqddot_dtau, "M^-1" + where);
    const std::vector<std::uint32_t> vertices = { 0, 5, 1129, 5, 600 };
    const auto J = pool.vertexJacobians(kBody, qs, vertices), J1 = one.vertexJacobians(kBody, qs, vertices);
    for (std::size_t k = 0; k < K; ++k)
      expectSameBits(std::vector<Eigen::MatrixXd>{ J[k].positions, J[k].J },
                     std::vector<Eigen::MatrixXd>{ J1[k].positions, J1[k].J }, "positions, J" + where);
    const auto g = gradients(K, 1130);
    expectSameBits(pool.backprop(kBody, g, qs), one.backprop(kBody, g, qs), "backprop" + where);
  }
  for (const auto& status : pool.status())
  {
    EXPECT_TRUE(status.up) << status.server << ": " << status.failure;
    EXPECT_GT(status.rates.count("backprop"), 0u) << status.server << " never answered a backprop shard";
  }
  EXPECT_TRUE(log.empty()) << log.front();
}

// The generated methods (client_declared.h), arguments in the client order: query<Srv> on a client
// gives the response that the hand-written method splits (its values, in the .srv's layout), and
// the pool's generated vertexJacobiansCompact (the pool writes no compact method) answers K
// configurations, sharded, with the bits of one instance.
TEST(RigidBodyPool, GeneratedMethodsAnswerAsTheHandWrittenOnes)
{
  std::vector<std::string> log;
  drb::RigidBodyPool pool(kPool, quietOptions(&log));
  drb::RigidBodyClient one(ros::NodeHandle(), "/pool1/rigid_body_server", ros::Duration(60.0));
  const auto qs = configurations(7);
  const auto M = one.massMatrices({}, flat(qs));
  const diff_rigid_body::GetMassMatrix::Response raw = one.query<diff_rigid_body::GetMassMatrix>(
      std::vector<std::string>{}, flat(qs));
  ASSERT_EQ(raw.mass_matrices.size(), 7u * 64u);
  for (std::size_t k = 0; k < 7; ++k)
    for (Eigen::Index r = 0; r < 8; ++r)
      for (Eigen::Index c = 0; c < 8; ++c)
        EXPECT_EQ(raw.mass_matrices[64 * k + 8 * r + c], M.M[k](r, c)) << "M, configuration " << k;
  EXPECT_TRUE(raw.derivatives.empty()) << "derivatives left out: false";

  const auto frames = one.frameJacobians(kBody, flat(qs), {}, { "panda_hand" }, drb::FrameReference::Local);
  const auto frames_raw = one.query<diff_rigid_body::GetFrameJacobians>(
      kBody, flat(qs), std::vector<double>{}, std::vector<std::string>{ "panda_hand" },
      static_cast<std::uint8_t>(drb::FrameReference::Local));
  ASSERT_EQ(frames_raw.jacobians.size(), 7u * 6u * 8u);
  for (std::size_t k = 0; k < 7; ++k)
    for (Eigen::Index r = 0; r < 6; ++r)
      for (Eigen::Index c = 0; c < 8; ++c)
        EXPECT_EQ(frames_raw.jacobians[48 * k + 8 * r + c], frames.J[k](r, c)) << "J, configuration " << k;

  const std::vector<std::uint32_t> vertices = { 0, 5, 1129 };
  const auto compact = pool.vertexJacobiansCompact(kBody, flat(qs), vertices);
  const auto compact1 = one.vertexJacobiansCompact(kBody, qs, vertices);
  ASSERT_EQ(compact1.size(), 7u);
  ASSERT_EQ(compact.positions.size(), 7u * 3u * 3u);
  ASSERT_EQ(compact.rotation_jacobians.size(), 7u * 3u * 3u * 8u);
  for (std::size_t k = 0; k < 7; ++k)
  {
    EXPECT_EQ(0, std::memcmp(compact.positions.data() + 9 * k, compact1[k].positions.data(), 9 * sizeof(double)))
        << "pool positions, configuration " << k;
    EXPECT_EQ(0, std::memcmp(compact.rotation_jacobians.data() + 72 * k, compact1[k].Jr.data(), 72 * sizeof(double)))
        << "pool Jr, configuration " << k;
  }
  EXPECT_TRUE(log.empty()) << log.front();
}

TEST(RigidBodyPool, BatchedCallsTakeOneEigenVectorPerConfiguration)
{
  // As RigidBodyClient: massMatrices, inverseDynamics, forwardDynamics with std::vector<VectorXd>
  // answer as with the K configurations concatenated, bit for bit.
  std::vector<std::string> log;
  drb::RigidBodyPool pool(kPool, quietOptions(&log));
  const std::vector<Eigen::VectorXd> qs = configurations(6);
  std::vector<double> flat;
  for (const Eigen::VectorXd& q : qs)
    flat.insert(flat.end(), q.data(), q.data() + q.size());
  const auto M = pool.massMatrices({ kBody }, flat), MX = pool.massMatrices({ kBody }, qs);
  const auto tau = pool.inverseDynamics({}, flat), tauX = pool.inverseDynamics({}, qs);
  const auto qddot = pool.forwardDynamics({ kBody }, flat), qddotX = pool.forwardDynamics({ kBody }, qs);
  ASSERT_EQ(MX.configurations, qs.size());
  for (std::size_t k = 0; k < qs.size(); ++k)
  {
    EXPECT_EQ(MX.at(k, 0), M.at(k, 0));
    EXPECT_EQ(tauX.tau[k], tau.tau[k]);
    EXPECT_EQ(qddotX.qddot[k], qddot.qddot[k]);
  }
}

TEST(RigidBodyPool, ApportionFollowsThroughput)
{
  EXPECT_EQ(drb::pool::apportion(8, { 3.0, 1.0 }), (std::vector<std::size_t>{ 6, 2 }));
  EXPECT_EQ(drb::pool::apportion(10, { 1.0, 1.0, 1.0 }), (std::vector<std::size_t>{ 4, 3, 3 }));
  EXPECT_EQ(drb::pool::apportion(5, { 0.0, 0.0 }), (std::vector<std::size_t>{ 3, 2 }));
  EXPECT_EQ(drb::pool::apportion(400, { 1000.0, 1.0 }), (std::vector<std::size_t>{ 399, 1 }));  // none starved
  EXPECT_EQ(drb::pool::apportion(1, { 1.0, 1.0 }), (std::vector<std::size_t>{ 1, 0 }));
}

TEST(RigidBodyPool, RefusesAnInstanceServingAnotherScene)
{
  std::vector<std::string> log;
  try
  {
    drb::RigidBodyPool pool({ "/pool1", "/other" }, quietOptions(&log));
    FAIL() << "a pool over the Panda and the default scene was accepted";
  }
  catch (const drb::PoolError& e)
  {
    EXPECT_NE(std::string(e.what()).find("/other/rigid_body_server"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("names"), std::string::npos) << e.what();
  }
}

TEST(RigidBodyPool, NoInstanceIsAClearError)
{
  std::vector<std::string> log;
  drb::PoolOptions options = quietOptions(&log);
  options.timeout = 0.5;
  try
  {
    drb::RigidBodyPool pool({ "/nobody1", "/nobody2" }, options);
    FAIL() << "a pool over namespaces nobody serves was accepted";
  }
  catch (const drb::PoolError& e)
  {
    const std::string what = e.what();
    EXPECT_NE(what.find("every instance is down"), std::string::npos) << what;
    EXPECT_NE(what.find("/nobody1/rigid_body_server"), std::string::npos) << what;
    EXPECT_NE(what.find("/nobody2/rigid_body_server"), std::string::npos) << what;
    EXPECT_EQ(e.failures().size(), 2u);
  }
}

TEST(RigidBodyPool, TakesNamespacesOrNodeNames)
{
  std::vector<std::string> log;
  drb::PoolOptions options = quietOptions(&log);
  options.timeout = 10.0;
  drb::RigidBodyPool pool({ "/pool1/rigid_body_server", "/pool2" }, options);
  const std::vector<drb::InstanceStatus> status = pool.status();
  ASSERT_EQ(status.size(), 2u);
  EXPECT_EQ(status[0].server, "/pool1/rigid_body_server");
  EXPECT_EQ(status[1].server, "/pool2/rigid_body_server");
  EXPECT_TRUE(status[0].up && status[1].up) << status[0].failure << status[1].failure;
}

TEST(RigidBodyPool, AClientGivenANamespaceNamesTheNodeBelowIt)
{
  drb::RigidBodyClient client(ros::NodeHandle(), "/pool1", ros::Duration(1.0));
  DRB_EXPECT_THROWS_MESSAGE(client.bodies(), drb::ConnectionError, "no node at /pool1",
                            "below /pool1 there is /pool1/rigid_body_server");
}

// Last. /pool2 respawns (a rostest may not lose a required node), but stays out of this pool until
// its retry time (5 s).
TEST(RigidBodyPool, InstanceKilledMidCallChangesNothing)
{
  std::vector<std::string> log;
  drb::RigidBodyPool pool(kPool, quietOptions(&log));
  drb::RigidBodyClient one(ros::NodeHandle(), "/pool1/rigid_body_server", ros::Duration(60.0));
  const auto qs = configurations(400);
  const auto g = gradients(qs.size(), 1130);
  const std::vector<Eigen::VectorXd> expected = one.backprop(kBody, g, qs);
  pool.backprop(kBody, g, qs);  // both instances connected and measured
  const int pid = nodePid("/pool2/rigid_body_server");
  ASSERT_GT(pid, 0) << "no pid for /pool2/rigid_body_server";
  ASSERT_EQ(0, ::kill(pid, SIGSTOP));  // it takes its shard and never answers...
  std::thread killer([pid] {
    std::this_thread::sleep_for(std::chrono::milliseconds(300));
    ::kill(pid, SIGKILL);  // ...and dies while the call waits on it
  });
  std::vector<Eigen::VectorXd> answer;
  EXPECT_NO_THROW(answer = pool.backprop(kBody, g, qs));
  killer.join();
  expectSameBits(answer, expected, "backprop with /pool2 killed mid-call");
  bool logged = false;
  for (const std::string& line : log)
    logged = logged || line.find("/pool2/rigid_body_server is down") != std::string::npos;
  EXPECT_TRUE(logged) << "no log line names /pool2 as down";
  const auto status = pool.status();
  EXPECT_TRUE(status[0].up);
  EXPECT_FALSE(status[1].up);
  expectSameBits(pool.backprop(kBody, g, qs), expected, "backprop on the survivor alone");
}

}  // namespace

int main(int argc, char** argv)
{
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "pool_cpp_test");
  ros::NodeHandle nh;
  return RUN_ALL_TESTS();
}
