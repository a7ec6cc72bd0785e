#include "semsegmap/sim/ray_scene.h"

#include <embree3/rtcore.h>

#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

namespace semsegmap::sim {

struct RayScene::Impl {
  RTCDevice device = nullptr;
  RTCScene top = nullptr;
  RTCScene static_scene = nullptr;
  std::vector<RTCScene> agent_scenes;
  std::vector<RTCGeometry> agent_instances;
  std::vector<Eigen::Matrix3f> agent_rotations;
};

namespace {

void checkDevice(RTCDevice device, const char* what) {
  const RTCError err = rtcGetDeviceError(device);
  if (err != RTC_ERROR_NONE)
    throw std::runtime_error(std::string("embree: ") + what + " failed with error " +
                             std::to_string(static_cast<int>(err)));
}

RTCGeometry makeTriangles(RTCDevice device, const Mesh& mesh) {
  RTCGeometry geom = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
  // The static world is built once and traced millions of times a frame: a better tree pays.
  rtcSetGeometryBuildQuality(geom, RTC_BUILD_QUALITY_HIGH);
  auto* v = static_cast<float*>(rtcSetNewGeometryBuffer(
      geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), mesh.vertices.size()));
  for (size_t k = 0; k < mesh.vertices.size(); ++k)
    for (int d = 0; d < 3; ++d) v[3 * k + d] = mesh.vertices[k][d];
  auto* idx = static_cast<unsigned*>(rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_INDEX, 0,
                                                             RTC_FORMAT_UINT3, 3 * sizeof(unsigned),
                                                             mesh.triangles.size()));
  for (size_t k = 0; k < mesh.triangles.size(); ++k)
    for (int d = 0; d < 3; ++d) idx[3 * k + d] = static_cast<unsigned>(mesh.triangles[k][d]);
  rtcCommitGeometry(geom);
  return geom;
}

RTCRay makeRay(const Eigen::Vector3f& o, const Eigen::Vector3f& d, float t_near, float t_far) {
  RTCRay ray;
  ray.org_x = o.x();
  ray.org_y = o.y();
  ray.org_z = o.z();
  ray.dir_x = d.x();
  ray.dir_y = d.y();
  ray.dir_z = d.z();
  ray.tnear = t_near;
  ray.tfar = t_far;
  ray.time = 0.0f;
  ray.mask = 0xffffffff;
  ray.id = 0;
  ray.flags = 0;
  return ray;
}

}  // namespace

RayScene::RayScene(const World& world) : world_(world), impl_(std::make_unique<Impl>()) {
  impl_->device = rtcNewDevice(nullptr);
  if (!impl_->device) throw std::runtime_error("embree: cannot create a device");
  impl_->top = rtcNewScene(impl_->device);
  // The static world is its own scene, instanced once with the identity, so that moving the
  // agents each frame rebuilds only a tree over a few instances, not over the whole world.
  impl_->static_scene = rtcNewScene(impl_->device);
  RTCGeometry stat = makeTriangles(impl_->device, world.mesh);
  rtcAttachGeometry(impl_->static_scene, stat);
  rtcReleaseGeometry(stat);
  rtcCommitScene(impl_->static_scene);
  RTCGeometry stat_inst = rtcNewGeometry(impl_->device, RTC_GEOMETRY_TYPE_INSTANCE);
  rtcSetGeometryInstancedScene(stat_inst, impl_->static_scene);
  const float identity[12] = {1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0};
  rtcSetGeometryTransform(stat_inst, 0, RTC_FORMAT_FLOAT3X4_COLUMN_MAJOR, identity);
  rtcCommitGeometry(stat_inst);
  rtcAttachGeometryByID(impl_->top, stat_inst, 0);
  rtcReleaseGeometry(stat_inst);
  for (size_t k = 0; k < world.agents.size(); ++k) {
    RTCScene s = rtcNewScene(impl_->device);
    RTCGeometry g = makeTriangles(impl_->device, world.agents[k].mesh);
    rtcAttachGeometry(s, g);
    rtcReleaseGeometry(g);
    rtcCommitScene(s);
    RTCGeometry inst = rtcNewGeometry(impl_->device, RTC_GEOMETRY_TYPE_INSTANCE);
    rtcSetGeometryInstancedScene(inst, s);
    rtcAttachGeometryByID(impl_->top, inst, static_cast<unsigned>(k + 1));
    impl_->agent_scenes.push_back(s);
    impl_->agent_instances.push_back(inst);
    impl_->agent_rotations.push_back(Eigen::Matrix3f::Identity());
  }
  checkDevice(impl_->device, "building the scene");
  setTime(0.0, Eigen::Vector2d(1e9, 1e9), 0.0);
}

RayScene::~RayScene() {
  for (auto g : impl_->agent_instances) rtcReleaseGeometry(g);
  for (auto s : impl_->agent_scenes) rtcReleaseScene(s);
  rtcReleaseScene(impl_->top);
  rtcReleaseScene(impl_->static_scene);
  rtcReleaseDevice(impl_->device);
}

void RayScene::setTime(double t, const Eigen::Vector2d& clear_xy, double clear_radius_m) {
  for (size_t k = 0; k < world_.agents.size(); ++k) {
    const Eigen::Vector3d p = world_.agents[k].poseAt(t);
    const bool hidden = (p.head<2>() - clear_xy).norm() < clear_radius_m;
    const float c = static_cast<float>(std::cos(p.z())), s = static_cast<float>(std::sin(p.z()));
    // Column-major 3x4: rotation about z, then translation (hidden agents go far below ground).
    const float xfm[12] = {c,
                           s,
                           0,
                           -s,
                           c,
                           0,
                           0,
                           0,
                           1,
                           static_cast<float>(p.x()),
                           static_cast<float>(p.y()),
                           hidden ? -1e4f : 0.0f};
    rtcSetGeometryTransform(impl_->agent_instances[k], 0, RTC_FORMAT_FLOAT3X4_COLUMN_MAJOR, xfm);
    rtcCommitGeometry(impl_->agent_instances[k]);
    Eigen::Matrix3f R;
    R << c, -s, 0, s, c, 0, 0, 0, 1;
    impl_->agent_rotations[k] = R;
  }
  rtcCommitScene(impl_->top);
  checkDevice(impl_->device, "updating the agents");
}

RayHit RayScene::intersect(const Eigen::Vector3f& origin, const Eigen::Vector3f& dir, float t_near,
                           float t_far) const {
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  RTCRayHit rh;
  rh.ray = makeRay(origin, dir, t_near, t_far);
  rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
  rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
  rtcIntersect1(impl_->top, &context, &rh);
  if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return RayHit{};
  return hitFrom(rh.hit.instID[0], rh.hit.primID, {rh.hit.Ng_x, rh.hit.Ng_y, rh.hit.Ng_z}, dir,
                 rh.ray.tfar);
}

RayHit RayScene::hitFrom(unsigned inst_id, unsigned prim_id, const Eigen::Vector3f& ng,
                         const Eigen::Vector3f& dir, float t) const {
  RayHit out;
  out.hit = true;
  out.t = t;
  Eigen::Vector3f n = ng;
  if (inst_id != 0) {
    const size_t k = inst_id - 1;
    const Agent& agent = world_.agents[k];
    out.surface = &agent.surfaces[agent.mesh.triangle_surface[prim_id]];
    n = impl_->agent_rotations[k] * n;
  } else {
    out.surface = &world_.surfaces[world_.mesh.triangle_surface[prim_id]];
  }
  n.normalize();
  if (n.dot(dir) > 0) n = -n;
  out.normal = n;
  return out;
}

void RayScene::intersect8(const bool active[kPacket], const Eigen::Vector3f origin[kPacket],
                          const Eigen::Vector3f dir[kPacket], float t_near, float t_far,
                          RayHit out[kPacket]) const {
  alignas(32) int valid[kPacket];
  alignas(32) RTCRayHit8 rh;
  for (int k = 0; k < kPacket; ++k) {
    valid[k] = active[k] ? -1 : 0;
    rh.ray.org_x[k] = origin[k].x();
    rh.ray.org_y[k] = origin[k].y();
    rh.ray.org_z[k] = origin[k].z();
    rh.ray.dir_x[k] = dir[k].x();
    rh.ray.dir_y[k] = dir[k].y();
    rh.ray.dir_z[k] = dir[k].z();
    rh.ray.tnear[k] = t_near;
    rh.ray.tfar[k] = t_far;
    rh.ray.time[k] = 0.0f;
    rh.ray.mask[k] = 0xffffffff;
    rh.ray.id[k] = static_cast<unsigned>(k);
    rh.ray.flags[k] = 0;
    rh.hit.geomID[k] = RTC_INVALID_GEOMETRY_ID;
    rh.hit.instID[0][k] = RTC_INVALID_GEOMETRY_ID;
  }
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  context.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
  rtcIntersect8(valid, impl_->top, &context, &rh);
  for (int k = 0; k < kPacket; ++k) {
    if (!active[k] || rh.hit.geomID[k] == RTC_INVALID_GEOMETRY_ID) {
      out[k] = RayHit{};
      continue;
    }
    out[k] = hitFrom(rh.hit.instID[0][k], rh.hit.primID[k],
                     {rh.hit.Ng_x[k], rh.hit.Ng_y[k], rh.hit.Ng_z[k]}, dir[k], rh.ray.tfar[k]);
  }
}

void RayScene::occluded8(const bool active[kPacket], const Eigen::Vector3f origin[kPacket],
                         const Eigen::Vector3f& dir, float t_near, float t_far,
                         bool out[kPacket]) const {
  alignas(32) int valid[kPacket];
  alignas(32) RTCRay8 ray;
  for (int k = 0; k < kPacket; ++k) {
    valid[k] = active[k] ? -1 : 0;
    ray.org_x[k] = origin[k].x();
    ray.org_y[k] = origin[k].y();
    ray.org_z[k] = origin[k].z();
    ray.dir_x[k] = dir.x();
    ray.dir_y[k] = dir.y();
    ray.dir_z[k] = dir.z();
    ray.tnear[k] = t_near;
    ray.tfar[k] = t_far;
    ray.time[k] = 0.0f;
    ray.mask[k] = 0xffffffff;
    ray.id[k] = static_cast<unsigned>(k);
    ray.flags[k] = 0;
  }
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  context.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
  rtcOccluded8(valid, impl_->top, &context, &ray);
  for (int k = 0; k < kPacket; ++k) out[k] = active[k] && ray.tfar[k] < 0.0f;
}

bool RayScene::occluded(const Eigen::Vector3f& origin, const Eigen::Vector3f& dir, float t_near,
                        float t_far) const {
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  RTCRay ray = makeRay(origin, dir, t_near, t_far);
  rtcOccluded1(impl_->top, &context, &ray);
  return ray.tfar < 0.0f;  // Embree sets tfar to -inf on a hit
}

}  // namespace semsegmap::sim
