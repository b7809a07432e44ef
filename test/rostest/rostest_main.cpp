// main() of the rostest gtest nodes (rigid_body_server_rostest and
// reliability_load_rostest): ros::init (so that rostest's __name:=
// and __log:= arguments are consumed), a background spinner for the
// subscriptions of the tests, then the tests.
#include <memory>

#include <gtest/gtest.h>
#include <ros/ros.h>

#include "server_under_test.h"

namespace drb_rostest
{
namespace
{
std::string serverName()
{
  return ros::NodeHandle("~").param<std::string>("server", "/rigid_body_server");
}
}  // namespace

RigidBodyClient& server()
{
  static std::unique_ptr<RigidBodyClient> client;
  if (!client)
    client = std::make_unique<RigidBodyClient>(ros::NodeHandle(), serverName(), ros::Duration(60.0));
  return *client;
}

drb_test::RawServices& rawServer()
{
  static std::unique_ptr<drb_test::RawServices> raw;
  if (!raw)
    raw = std::make_unique<drb_test::RawServices>(serverName());
  return *raw;
}
}  // namespace drb_rostest

int main(int argc, char** argv)
{
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "rigid_body_server_test");
  ros::NodeHandle nh;
  ros::AsyncSpinner spinner(2);
  spinner.start();
  const int result = RUN_ALL_TESTS();
  spinner.stop();
  ros::shutdown();
  return result;
}
