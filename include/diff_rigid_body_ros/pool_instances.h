// The instances of diff_rigid_body_ros::RigidBodyPool (rigid_body_pool.h) and their threads: one
// Worker per instance runs that instance's calls one after the other, so its RigidBodyClient (not
// thread-safe) is only ever used by that thread; a Round waits, with a deadline, for the shards of
// one call; a down instance is marked, logged and probed here.
#pragma once

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstddef>
#include <deque>
#include <exception>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <stdexcept>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "diff_rigid_body_ros/pool_shards.h"
#include "diff_rigid_body_ros/rigid_body_client.h"

namespace diff_rigid_body_ros
{
struct PoolOptions
{
  std::string server = "rigid_body_server";  ///< the node's name within each namespace
  double timeout = 30.0;         ///< [s] how long the constructor waits for each instance
  double call_timeout = 30.0;    ///< [s] an instance with no answer by then is down; its shard goes elsewhere
  double retry_interval = 5.0;   ///< [s] how often a down instance is asked again
  double probe_timeout = 2.0;    ///< [s] how long such a question waits for the instance's service
  double rate_smoothing = 0.3;   ///< weight of the newest throughput measurement in an instance's average
  std::function<void(const std::string&)> log;  ///< failures and recoveries (default: ROS_WARN)
};

/// No instance could answer, or an instance serves another scene. failures(): server -> what happened.
class PoolError : public std::runtime_error
{
public:
  PoolError(const std::string& what, std::map<std::string, std::string> failures)
    : std::runtime_error(what), failures_(std::move(failures))
  {
  }
  const std::map<std::string, std::string>& failures() const { return failures_; }

private:
  std::map<std::string, std::string> failures_;
};

struct InstanceStatus
{
  std::string server;
  bool up = false;
  std::string failure;                   ///< the last failure ("" while up)
  std::map<std::string, double> rates;   ///< service -> measured configurations/s
};

namespace pool
{
/// A detached thread that runs submitted jobs in order. Destroying the Worker ends the thread
/// after its current job (never joined: a job blocked in a call to a hung instance must not block
/// the owner).
class Worker
{
public:
  Worker() : state_(std::make_shared<State>())
  {
    std::thread([state = state_] { run(*state); }).detach();
  }
  ~Worker()
  {
    {
      std::lock_guard<std::mutex> lock(state_->mutex);
      state_->stop = true;
    }
    state_->wake.notify_all();
  }
  Worker(const Worker&) = delete;
  Worker& operator=(const Worker&) = delete;

  void submit(std::function<void()> job)
  {
    {
      std::lock_guard<std::mutex> lock(state_->mutex);
      state_->jobs.push_back(std::move(job));
    }
    state_->wake.notify_all();
  }

private:
  struct State
  {
    std::mutex mutex;
    std::condition_variable wake;
    std::deque<std::function<void()>> jobs;
    bool stop = false;
  };

  static void run(State& state)
  {
    for (;;)
    {
      std::function<void()> job;
      {
        std::unique_lock<std::mutex> lock(state.mutex);
        state.wake.wait(lock, [&] { return state.stop || !state.jobs.empty(); });
        if (state.stop)
          return;
        job = std::move(state.jobs.front());
        state.jobs.pop_front();
      }
      job();
    }
  }

  std::shared_ptr<State> state_;
};

/// One node of a pool: its client and worker, whether it serves, and its measured throughput per
/// service [configurations/s]. `up` and `busy` are read by the pool's thread and written by the
/// worker; the rest is guarded by `mutex`.
struct Instance
{
  Instance(const ros::NodeHandle& nh, const std::string& server_name, ros::Duration probe_timeout)
    : server(nh.resolveName(server_name)), client(nh, server, probe_timeout)
  {
    client.setReconnect(false);
  }

  std::string server;
  RigidBodyClient client;  ///< used by `worker`'s thread only
  Worker worker;
  std::atomic<bool> up{ false };
  std::atomic<bool> busy{ false };  ///< a call or probe of this instance is in flight

  std::mutex mutex;
  std::string failure = "not connected yet";
  std::map<std::string, double> rates;
  std::chrono::steady_clock::time_point retry_at;

  void record(const std::string& service, std::size_t configurations, double seconds, double smoothing)
  {
    if (configurations == 0 || !(seconds > 0.0))
      return;
    const double measured = static_cast<double>(configurations) / seconds;
    std::lock_guard<std::mutex> lock(mutex);
    const auto found = rates.find(service);
    rates[service] = found == rates.end() ? measured : (1.0 - smoothing) * found->second + smoothing * measured;
  }
};

/// Jobs of one call, each filling its own Piece; wait() returns when all have finished or at the
/// deadline. Shared with the jobs, so a job that outlives the call writes into a live object.
template <typename Piece>
struct Round
{
  std::mutex mutex;
  std::condition_variable finished_one;
  std::deque<Piece> pieces;  ///< stable addresses while pieces are added
  std::deque<bool> finished;

  void finish(std::size_t i)
  {
    {
      std::lock_guard<std::mutex> lock(mutex);
      finished[i] = true;
    }
    finished_one.notify_all();
  }

  /// Which pieces finished within `timeout`.
  std::deque<bool> wait(std::chrono::duration<double> timeout)
  {
    std::unique_lock<std::mutex> lock(mutex);
    finished_one.wait_for(lock, timeout, [&] {
      for (bool done : finished)
        if (!done)
          return false;
      return true;
    });
    return finished;
  }
};

/// What jobs need from the pool, even after it is gone: the options and the scene it serves.
struct Shared
{
  PoolOptions options;
  diff_rigid_body::GetBodies::Response scene;
};

/// The message of an exception caught as std::exception_ptr.
inline std::string describe(const std::exception_ptr& error)
{
  try
  {
    std::rethrow_exception(error);
  }
  catch (const std::exception& e)
  {
    return e.what();
  }
  catch (...)
  {
    return "unknown exception";
  }
}

/// Marks `instance` down with `failure`, logs it by name and schedules its next probe.
inline void markDown(Instance& instance, const std::string& failure, const Shared& shared)
{
  {
    std::lock_guard<std::mutex> lock(instance.mutex);
    instance.up = false;
    instance.failure = failure;
    instance.retry_at =
        std::chrono::steady_clock::now() + std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                                               std::chrono::duration<double>(shared.options.retry_interval));
  }
  shared.options.log("RigidBodyPool: instance " + instance.server + " is down (" + failure +
                     "); its work goes to the others");
}

/// On the instance's worker: get_bodies again; the instance rejoins if it serves the same scene.
inline void probe(const std::shared_ptr<Instance>& instance, const std::shared_ptr<const Shared>& shared)
{
  try
  {
    diff_rigid_body::GetBodies srv;
    instance->client.call("get_bodies", srv);
    const std::string differs = sceneMismatch(shared->scene, srv.response);
    std::lock_guard<std::mutex> lock(instance->mutex);
    if (differs.empty())
      instance->up = true;
    else
      instance->failure = "serves another scene (" + differs + " differ)";
  }
  catch (const std::exception&)  // still down (ConnectionError), or refusing get_bodies
  {
  }
  {
    std::lock_guard<std::mutex> lock(instance->mutex);
    instance->retry_at = std::chrono::steady_clock::now() +
                         std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                             std::chrono::duration<double>(shared->options.retry_interval));
  }
  if (instance->up)
    shared->options.log("RigidBodyPool: instance " + instance->server + " is back");
  instance->busy = false;
}

/// get_bodies of every instance, concurrently on their workers (each waits up to `timeout` [s] for
/// the service). Per instance: its answer, or the error of an unreachable one; `finished` says
/// which answered or failed within timeout + 5 s.
struct SceneAnswers
{
  using Piece = std::pair<diff_rigid_body::GetBodies, std::exception_ptr>;
  std::shared_ptr<Round<Piece>> round = std::make_shared<Round<Piece>>();
  std::deque<bool> finished;
};
inline SceneAnswers askScenes(const std::vector<std::shared_ptr<Instance>>& instances, double timeout)
{
  SceneAnswers answers;
  auto round = answers.round;
  for (std::size_t i = 0; i < instances.size(); ++i)
  {
    round->pieces.emplace_back();
    round->finished.push_back(false);
    instances[i]->worker.submit([round, i, instance = instances[i], timeout] {
      SceneAnswers::Piece& piece = round->pieces[i];
      try
      {
        if (!ros::service::waitForService(instance->server + "/get_bodies", ros::Duration(timeout)))
          throw ConnectionError(
              diff_rigid_body_ros::detail::missingNodeMessage(instance->server, instance->server + "/get_bodies",
                                                              timeout));
        instance->client.call("get_bodies", piece.first);
      }
      catch (...)
      {
        piece.second = std::current_exception();
      }
      round->finish(i);
    });
  }
  answers.finished = round->wait(std::chrono::duration<double>(timeout + 5.0));
  return answers;
}

}  // namespace pool
}  // namespace diff_rigid_body_ros
