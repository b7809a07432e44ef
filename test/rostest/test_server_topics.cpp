// The node's topics: ~states is published (latched, on every change, and at
// the publish rate while it has a subscriber); ~set_states applies a valid BodyStateArray like
// set_state and drops an invalid one whole, with a warning (on /rosout)
// that names the problem.
//
// Runs in topics.test. Every test leaves the node's state as it found it
// (RestoresState), so the tests run in any order.
#include <condition_variable>
#include <limits>
#include <mutex>

#include <gtest/gtest.h>

#include <diff_rigid_body/BodyStateArray.h>
#include <rosgraph_msgs/Log.h>

#include "server_under_test.h"

namespace drb_rostest
{
namespace
{
const double kTimeout = 10.0;  // s

/// Keeps the ~states messages received.
class StatesRecorder
{
public:
  StatesRecorder()
  {
    subscriber_ = ros::NodeHandle().subscribe(server().server() + "/states", 100, &StatesRecorder::onMessage, this);
  }
  /// Waits for a message for which `accept` is true; returns it (or throws).
  template <typename Predicate>
  drb::BodyStateArray waitFor(Predicate accept)
  {
    std::unique_lock<std::mutex> lock(mutex_);
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(kTimeout);
    std::size_t seen = 0;
    while (true)
    {
      for (; seen < messages_.size(); ++seen)
        if (accept(messages_[seen]))
          return messages_[seen];
      if (changed_.wait_until(lock, deadline) == std::cv_status::timeout)
        throw std::runtime_error("no matching ~states message within " + std::to_string(kTimeout) + " s");
    }
  }

private:
  void onMessage(const drb::BodyStateArray::ConstPtr& message)
  {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      messages_.push_back(*message);
    }
    changed_.notify_all();
  }
  std::mutex mutex_;
  std::condition_variable changed_;
  std::vector<drb::BodyStateArray> messages_;
  ros::Subscriber subscriber_;
};

/// Keeps the node's warnings from /rosout.
class WarningRecorder
{
public:
  WarningRecorder()
  {
    subscriber_ = ros::NodeHandle().subscribe("/rosout", 100, &WarningRecorder::onMessage, this);
  }
  /// True once a warning of the node contains every fragment.
  bool waitFor(const std::vector<std::string>& fragments)
  {
    const ros::WallTime deadline = ros::WallTime::now() + ros::WallDuration(kTimeout);
    while (ros::WallTime::now() < deadline)
    {
      {
        std::lock_guard<std::mutex> lock(mutex_);
        for (const std::string& text : warnings_)
        {
          bool all = true;
          for (const std::string& fragment : fragments)
            all = all && containsIgnoringCase(text, fragment);
          if (all)
            return true;
        }
      }
      ros::WallDuration(0.01).sleep();
    }
    return false;
  }
  /// Waits until `count` nodes publish on /rosout to this subscriber.
  bool waitForPublishers(std::uint32_t count)
  {
    const ros::WallTime deadline = ros::WallTime::now() + ros::WallDuration(kTimeout);
    while (subscriber_.getNumPublishers() < count && ros::WallTime::now() < deadline)
      ros::WallDuration(0.01).sleep();
    return subscriber_.getNumPublishers() >= count;
  }
  std::vector<std::string> warnings()
  {
    std::lock_guard<std::mutex> lock(mutex_);
    return warnings_;
  }

private:
  void onMessage(const rosgraph_msgs::Log::ConstPtr& message)
  {
    if (message->name != server().server() || message->level < rosgraph_msgs::Log::WARN)
      return;
    std::lock_guard<std::mutex> lock(mutex_);
    warnings_.push_back(message->msg);
  }
  std::mutex mutex_;
  std::vector<std::string> warnings_;
  ros::Subscriber subscriber_;
};

class Topics : public RestoresState
{
protected:
  void SetUp() override
  {
    RestoresState::SetUp();
    publisher_ = ros::NodeHandle().advertise<drb::BodyStateArray>(server().server() + "/set_states", 10);
    const ros::WallTime deadline = ros::WallTime::now() + ros::WallDuration(kTimeout);
    while (publisher_.getNumSubscribers() == 0 && ros::WallTime::now() < deadline)
      ros::WallDuration(0.01).sleep();
    ASSERT_GT(publisher_.getNumSubscribers(), 0u) << "the node does not subscribe to ~set_states";
  }

  void publish(const std::vector<drb::BodyState>& states)
  {
    drb::BodyStateArray message;
    message.header.stamp = ros::Time::now();
    message.states = states;
    publisher_.publish(message);
  }

  NamedStates currentState() { return server().getState(); }

  /// Polls get_state until it equals `expected` bit for bit.
  bool waitForState(const NamedStates& expected)
  {
    const ros::WallTime deadline = ros::WallTime::now() + ros::WallDuration(kTimeout);
    while (ros::WallTime::now() < deadline)
    {
      if (bitwiseEqual(currentState(), expected))
        return true;
      ros::WallDuration(0.005).sleep();
    }
    return false;
  }

  ros::Publisher publisher_;
};

NamedStates replaced(NamedStates states, const std::string& name, const Vector6d& q)
{
  for (auto& state : states)
    if (state.first == name)
      state.second = q;
  return states;
}

/// The message carries exactly `states`, bit for bit.
bool carries(const drb::BodyStateArray& message, const NamedStates& states)
{
  return bitwiseEqual(namedStates(message.states), states);
}
}  // namespace

TEST_F(Topics, StatesArePublishedAndFollowChanges)
{
  StatesRecorder recorder;
  const NamedStates current = currentState();
  // Latched / periodic: a message with the current state arrives without a change.
  const drb::BodyStateArray first = recorder.waitFor([&](const drb::BodyStateArray& m) { return carries(m, current); });
  EXPECT_EQ(first.header.frame_id, "world");
  EXPECT_FALSE(first.header.stamp.isZero());

  Vector6d q;
  q << 5.5, -0.25, 1e3, 0.5, -0.5, 2.0;
  server().setState("roller", q);
  const NamedStates changed = replaced(current, "roller", q);
  EXPECT_NO_THROW(recorder.waitFor([&](const drb::BodyStateArray& m) { return carries(m, changed); }))
      << describe(changed);
}

TEST_F(Topics, SetStatesAppliesAValidMessage)
{
  const NamedStates before = currentState();
  Vector6d brick, tet;
  brick << -0.5, 0.25, 123.0, 1.0, -1.0, 0.5;
  tet << 0.0, kPi / 2, -kPi, -0.0, 3.0, 4.0;
  StatesRecorder recorder;
  publish({ bodyState("tet", tet), bodyState("brick", brick) });
  const NamedStates expected = replaced(replaced(before, "brick", brick), "tet", tet);
  EXPECT_TRUE(waitForState(expected)) << "expected " << describe(expected) << "\ngot " << describe(currentState());
  // The change is published on ~states as well.
  EXPECT_NO_THROW(recorder.waitFor([&](const drb::BodyStateArray& m) { return carries(m, expected); }));
}

TEST_F(Topics, SetStatesDropsAnInvalidMessageWhole)
{
  const NamedStates before = currentState();
  Vector6d tet_new, nan_q, marker;
  tet_new << 1.0, 1.0, 1.0, 1.0, 1.0, 1.0;
  nan_q << 0.0, std::numeric_limits<double>::quiet_NaN(), 0.0, 0.0, 0.0, 0.0;
  marker << 0.125, -0.125, 0.25, -0.25, 0.5, -0.5;

  WarningRecorder rosout;
  ASSERT_TRUE(rosout.waitForPublishers(2)) << "not connected to the node's /rosout";  // the node and this test
  // Each invalid message carries a valid state for tet that must NOT be applied.
  publish({ bodyState("tet", tet_new), bodyState("brick", nan_q) });                   // non-finite
  publish({ bodyState("tet", tet_new), bodyState("nope", marker) });                   // unknown body
  publish({ bodyState("tet", tet_new), bodyState("tet", marker) });                    // repeated body
  // Messages on one connection are handled in order: once this valid one
  // has been applied, the invalid ones before it have been handled.
  publish({ bodyState("roller", marker) });
  const NamedStates expected = replaced(before, "roller", marker);
  EXPECT_TRUE(waitForState(expected)) << "expected " << describe(expected) << "\ngot " << describe(currentState());
  // The warning (throttled: the first of the three) names the field and the body.
  EXPECT_TRUE(rosout.waitFor({ "set_states", "states[1]", "brick", "finite" }))
      << "warnings seen: " << ::testing::PrintToString(rosout.warnings());

  // The node still takes valid messages and service calls.
  ASSERT_NO_THROW(server().bodies());
  publish({ bodyState("tet", tet_new) });
  EXPECT_TRUE(waitForState(replaced(expected, "tet", tet_new)));
  // Leave the node's set_states warning throttle (1 s, rigid_body_server.cpp)
  // as found, so that a repeat of this test sees its warning again.
  ros::WallDuration(1.1).sleep();
}

}  // namespace drb_rostest
