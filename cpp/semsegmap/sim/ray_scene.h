// The world as an Embree scene: static geometry plus one instance per moving agent, whose
// transforms are set for the time of each frame. Queries are thread-safe between setTime calls.
#pragma once

#include <memory>

#include <Eigen/Core>

#include "semsegmap/sim/world.h"

namespace semsegmap::sim {

struct RayHit {
  bool hit = false;
  float t = 0.0f;
  Eigen::Vector3f normal{0, 0, 1};  // unit, world frame, facing the ray's origin
  const Surface* surface = nullptr;
};

class RayScene {
 public:
  // Keeps a reference to `world`, which must outlive the scene.
  explicit RayScene(const World& world);
  ~RayScene();
  RayScene(const RayScene&) = delete;
  RayScene& operator=(const RayScene&) = delete;

  // Places the agents where they are at time t. Agents within `clear_radius_m` of `clear_xy`
  // (the ego vehicle) are hidden, because the simulation has no traffic rules to keep them out
  // of its way and a sensor inside a car sees nothing useful.
  void setTime(double t, const Eigen::Vector2d& clear_xy, double clear_radius_m);

  RayHit intersect(const Eigen::Vector3f& origin, const Eigen::Vector3f& dir, float t_near,
                   float t_far) const;
  bool occluded(const Eigen::Vector3f& origin, const Eigen::Vector3f& dir, float t_near,
                float t_far) const;

  // Eight rays at once (Embree packets): neighbouring camera pixels traverse the same nodes, so
  // tracing them together is much cheaper than one by one. Lanes with active[k] false are skipped.
  static constexpr int kPacket = 8;
  void intersect8(const bool active[kPacket], const Eigen::Vector3f origin[kPacket],
                  const Eigen::Vector3f dir[kPacket], float t_near, float t_far,
                  RayHit out[kPacket]) const;
  void occluded8(const bool active[kPacket], const Eigen::Vector3f origin[kPacket],
                 const Eigen::Vector3f& dir, float t_near, float t_far, bool out[kPacket]) const;

  const World& world() const { return world_; }

 private:
  struct Impl;
  RayHit hitFrom(unsigned inst_id, unsigned prim_id, const Eigen::Vector3f& ng,
                 const Eigen::Vector3f& dir, float t) const;

  const World& world_;
  std::unique_ptr<Impl> impl_;
};

}  // namespace semsegmap::sim
