// The pipeline on a running robot: scans, pictures and odometry come in as the drivers publish
// them (each with its time), frames are made of them (frame_assembly.h) and worked on one at a
// time by a worker thread, and poses come out as they are found. No ROS here: a ROS node (or a
// program watching a folder) is a thin shell that feeds this and publishes what it gives.
//
// Falling behind: frames wait in a queue of max_queued_frames; a frame that finds it full pushes
// out the oldest waiting one, which is dropped and counted. The newest scan is what a robot
// needs localized, and the caller (a driver's callback) is never blocked. Offline
// (never_drop), the caller waits for room instead, so that every frame is worked on in order
// and the same recording gives the same poses.
#pragma once

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstddef>
#include <deque>
#include <functional>
#include <mutex>
#include <thread>
#include <vector>

#include "semsegmap/pipeline/frame_assembly.h"
#include "semsegmap/pipeline/modes.h"

namespace semsegmap {

struct LiveConfig {
  FrameAssemblyConfig assembly;
  size_t max_queued_frames = 2;  // frames waiting for the worker; more drops the oldest
  bool never_drop = false;       // offline: the caller waits for room instead
};

// One localization as it leaves the live session.
struct LivePose {
  LocalizationRecord record;            // record.T_map_base: the robot in the map
  Pose T_odom_base = Pose::Identity();  // the odometry's pose of the same frame
  // What a node publishes as map -> odom: T_map_base * inverse(T_odom_base), so that the robot's
  // own odometry chain (odom -> base) stays its drivers'.
  Pose T_map_odom = Pose::Identity();
  double latency_ms = 0.0;  // from the scan's arrival (addScan) to its pose
};

struct LiveStats {
  AssemblyStats assembly;
  size_t processed = 0;                                // frames the worker finished
  size_t dropped = 0;                                  // frames pushed out of the full queue
  size_t localized = 0;                                // poses given
  size_t max_queued = 0;                               // the most frames that waited at once
  double mean_latency_ms = 0.0, max_latency_ms = 0.0;  // scan arrival -> frame finished
};

class LiveSession {
 public:
  // Works on one frame on the worker thread and gives the poses it found (none for mapping).
  using Process = std::function<std::vector<LivePose>(const Frame&)>;
  using Clock = std::chrono::steady_clock;

  LiveSession(const LiveConfig& config, Process process);
  ~LiveSession();  // stops the worker; frames still waiting are not worked on
  LiveSession(const LiveSession&) = delete;
  LiveSession& operator=(const LiveSession&) = delete;

  // Thread-safe; never block unless never_drop. A message that cannot be used (a picture of a
  // camera the rig does not have, a scan without a finite time) throws std::invalid_argument.
  void addScan(ScanMessage scan);
  void addPicture(size_t camera, PictureMessage picture);
  void addOdometry(const StampedPose& odometry);

  // A frame already made (a recording's): queued after the frames made before it, without the
  // assembly. What the offline commands feed (runMapping, runLocalization: never_drop).
  void addFrame(Frame frame);

  std::vector<LivePose> poll();  // the poses found since the last call, in order
  // The end of the input: the waiting scans are made into frames with what they have, the queue
  // is worked off, the worker stops. The poses not yet polled stay for poll(). Once.
  void finish();
  LiveStats stats() const;
  // A worker's exception, rethrown in the caller's thread by the next call here (the worker
  // stops at the first one: a frame it could not work on leaves no state to go on from).

 private:
  struct Queued {
    Frame frame;
    Clock::time_point arrival;
  };
  void enqueue(std::vector<Frame> frames);
  void work();
  void rethrow();
  LiveConfig config_;
  Process process_;
  mutable std::mutex in_mutex_;  // the assembler and the arrivals
  FrameAssembler assembler_;
  std::deque<std::pair<double, Clock::time_point>> arrivals_;  // scan time -> arrival
  mutable std::mutex queue_mutex_;  // the queue, the poses out, the stats
  std::condition_variable queued_, room_;
  std::deque<Queued> queue_;
  std::vector<LivePose> out_;
  LiveStats stats_;
  double latency_sum_ms_ = 0.0;
  bool closing_ = false, stopping_ = false, finished_ = false;
  std::exception_ptr failure_;
  std::thread worker_;
};

// The Process of a localizing robot: `session` works on each frame, and the localizations it
// adds become LivePoses. The session must outlive the live session that calls it.
LiveSession::Process localizingProcess(LocalizationSession& session);

}  // namespace semsegmap
