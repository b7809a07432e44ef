// The rigid_body_server under test, through the shipped C++ client
// (include/diff_rigid_body_ros/rigid_body_client.h), raw calls for what the
// client cannot express, a fixture that leaves the node's state as it found
// it, and state and frame conversions.
#pragma once

#include <cctype>
#include <cstring>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Geometry>
#include <geometry_msgs/Transform.h>
#include <gtest/gtest.h>
#include <ros/ros.h>

#include <diff_rigid_body/BodyState.h>
#include <diff_rigid_body_ros/rigid_body_client.h>

#include "../support/raw_service.h"
#include "fixture_scene.h"

namespace drb_rostest
{
namespace drb = diff_rigid_body;
using diff_rigid_body_ros::RigidBodyClient;
using diff_rigid_body_ros::ServiceError;
/// get_state's answer and set_state's request: (body name, q) in order.
using NamedStates = std::vector<std::pair<std::string, Vector6d>>;

/// The server under test: private parameter ~server of the test node
/// (default "/rigid_body_server"), connected on first use.
RigidBodyClient& server();

/// Raw calls to the same server.
drb_test::RawServices& rawServer();

/// Saves the node's state before each test and sets it back after, bit for
/// bit, so that tests that change it can run in any order.
class RestoresState : public ::testing::Test
{
protected:
  void SetUp() override { saved_ = server().getState(); }
  void TearDown() override { server().setState(saved_); }

  NamedStates saved_;
};

// ---------------------------------------------------------------------------
// Conversions.

inline drb::BodyState bodyState(const std::string& name, const Vector6d& q)
{
  drb::BodyState state;
  state.name = name;
  state.q.assign(q.data(), q.data() + 6);
  return state;
}

inline NamedStates namedStates(const std::vector<drb::BodyState>& states)
{
  NamedStates out;
  for (const drb::BodyState& state : states)
  {
    if (state.q.size() != 6)  // a free body's x is q (6 values)
      throw std::runtime_error("state of '" + state.name + "' has " + std::to_string(state.q.size()) + " values, not 6");
    out.emplace_back(state.name, Eigen::Map<const Vector6d>(state.q.data()));
  }
  return out;
}

inline std::vector<double> toStdVector(const Vector6d& q)
{
  return std::vector<double>(q.data(), q.data() + 6);
}

/// Same names, and q equal bit for bit (memcmp: NaN payloads and -0 count).
inline bool bitwiseEqual(const NamedStates& a, const NamedStates& b)
{
  if (a.size() != b.size())
    return false;
  for (std::size_t i = 0; i < a.size(); ++i)
    if (a[i].first != b[i].first || std::memcmp(a[i].second.data(), b[i].second.data(), sizeof(double) * 6) != 0)
      return false;
  return true;
}

inline std::string describe(const NamedStates& states)
{
  std::ostringstream out;
  out.precision(17);
  for (const auto& state : states)
  {
    out << state.first << " [";
    for (int i = 0; i < 6; ++i)
      out << " " << state.second[i];
    out << " ]; ";
  }
  return out.str();
}

/// A tf transform as an isometry.
inline Eigen::Isometry3d toIsometry(const geometry_msgs::Transform& transform)
{
  Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
  X.linear() = Eigen::Quaterniond(transform.rotation.w, transform.rotation.x, transform.rotation.y,
                                  transform.rotation.z)
                   .toRotationMatrix();
  X.translation() << transform.translation.x, transform.translation.y, transform.translation.z;
  return X;
}

/// True if `text` contains `fragment`, ignoring case.
inline bool containsIgnoringCase(std::string text, std::string fragment)
{
  for (char& c : text)
    c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  for (char& c : fragment)
    c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return text.find(fragment) != std::string::npos;
}

}  // namespace drb_rostest
