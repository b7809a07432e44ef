// main() of the rostest gtest node: ros::init (so that rostest's __name:=
// and __log:= arguments are consumed), a background spinner for the
// subscriptions of the tests, then the tests.
#include <memory>

#include <gtest/gtest.h>
#include <ros/ros.h>

#include "server_client.h"

namespace drb_rostest
{
ServerClient& server()
{
  static std::unique_ptr<ServerClient> client;
  if (!client)
  {
    const std::string name = ros::NodeHandle("~").param<std::string>("server", "/rigid_body_server");
    client = std::make_unique<ServerClient>(name);
  }
  return *client;
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
