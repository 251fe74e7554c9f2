#include "derender/mesh_sample.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <mutex>

#include <embree3/rtcore.h>

#include "core/error.h"

namespace ibrdf {
namespace {

// The first Embree error of a device, kept for the message of the Error thrown after the call.
struct DeviceErrors {
  std::mutex mutex;
  std::string first;
};

void OnEmbreeError(void* user, RTCError code, const char* text) {
  auto* errors = static_cast<DeviceErrors*>(user);
  std::lock_guard<std::mutex> lock(errors->mutex);
  if (errors->first.empty()) errors->first = "Embree error " + std::to_string(int(code)) + ": " + (text ? text : "");
}

// One device and one scene, released together.
struct Scene {
  RTCDevice device = nullptr;
  RTCScene scene = nullptr;
  DeviceErrors errors;

  explicit Scene(const std::string& source) {
    device = rtcNewDevice(nullptr);
    if (!device)
      ThrowError(source,
                 "cannot create an Embree device (error " + std::to_string(int(rtcGetDeviceError(nullptr))) + ")");
    rtcSetDeviceErrorFunction(device, OnEmbreeError, &errors);
    scene = rtcNewScene(device);
    // Robust traversal: no ray slips through a shared edge or vertex of neighbouring triangles.
    rtcSetSceneFlags(scene, RTC_SCENE_FLAG_ROBUST);
    rtcSetSceneBuildQuality(scene, RTC_BUILD_QUALITY_HIGH);
  }
  ~Scene() {
    if (scene) rtcReleaseScene(scene);
    if (device) rtcReleaseDevice(device);
  }
  void Commit(const std::string& source) {
    rtcCommitScene(scene);
    if (rtcGetDeviceError(device) != RTC_ERROR_NONE || !errors.first.empty()) {
      ThrowError(source, "building the ray-tracing scene failed: " + errors.first);
    }
  }
};

void InitRay(const Eigen::Vector3f& origin, const Eigen::Vector3f& direction, float t_near, float t_far, RTCRay* ray) {
  ray->org_x = origin.x();
  ray->org_y = origin.y();
  ray->org_z = origin.z();
  ray->tnear = t_near;
  ray->dir_x = direction.x();
  ray->dir_y = direction.y();
  ray->dir_z = direction.z();
  ray->time = 0.0f;
  ray->tfar = t_far;
  ray->mask = 0xFFFFFFFFu;
  ray->id = 0;
  ray->flags = 0;
}

void InitRayHit(const Eigen::Vector3f& origin, const Eigen::Vector3f& direction, RTCRayHit* rayhit) {
  InitRay(origin, direction, 0.0f, std::numeric_limits<float>::infinity(), &rayhit->ray);
  rayhit->hit.geomID = RTC_INVALID_GEOMETRY_ID;
  rayhit->hit.primID = RTC_INVALID_GEOMETRY_ID;
  rayhit->hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
}

}  // namespace

struct MeshSample::Embree {
  explicit Embree(const std::string& source) : scene(source) {}
  Scene scene;
};

struct QuadOccluders::Embree {
  explicit Embree(const std::string& source) : scene(source) {}
  Scene scene;
};

MeshSample::MeshSample(const ScanMesh& mesh, const Sim3d& world_from_mesh, const std::string& source) {
  const size_t n = mesh.points.size();
  if (mesh.faces.empty()) {
    ThrowError(source,
               "the mesh has no faces: the derenderer intersects rays with triangles (`ibrdf scan` "
               "tessellates range scans and reconstructs point clouds)");
  }
  if (mesh.normals.size() != n) {
    ThrowError(source, mesh.normals.empty()
                           ? "the mesh has no per-point normals (nx, ny, nz): run `ibrdf scan` on it, which fits "
                             "local-plane normals"
                           : "the mesh has " + std::to_string(mesh.normals.size()) + " normals for " +
                                 std::to_string(n) + " points");
  }
  if (!mesh.fit_rms_m.empty() && mesh.fit_rms_m.size() != n)
    ThrowError(source, "quality (fit RMS) is not one per point");
  if (!mesh.fit_neighbours.empty() && mesh.fit_neighbours.size() != n)
    ThrowError(source, "fit_neighbours is not one per point");
  if (!(world_from_mesh.scale > 0.0)) ThrowError(source, "world_from_mesh scale must be positive");
  RequireFinitePoints(mesh, source);
  if (n > size_t(std::numeric_limits<int>::max()) || mesh.faces.size() > size_t(std::numeric_limits<unsigned>::max())) {
    ThrowError(source, "the mesh is too large");
  }

  // World points in double; the origin is their centroid, computed from offsets to the first point so
  // that far-away coordinates do not lose digits in the sum.
  std::vector<Eigen::Vector3d> world(n);
  for (size_t i = 0; i < n; ++i) world[i] = world_from_mesh * mesh.points[i];
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (size_t i = 0; i < n; ++i) sum += world[i] - world[0];
  origin_ = world[0] + sum / double(n);
  points_.resize(n);
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
  for (size_t i = 0; i < n; ++i) {
    points_[i] = world[i] - origin_;
    lo = lo.cwiseMin(points_[i]);
    hi = hi.cwiseMax(points_[i]);
  }
  const Eigen::Vector3d box_center = 0.5 * (lo + hi);
  double radius = 0.0;
  for (const Eigen::Vector3d& p : points_) radius = std::max(radius, (p - box_center).norm());
  bounding_center_ = origin_ + box_center;
  bounding_radius_ = radius;
  if (!(radius > 0.0)) ThrowError(source, "the mesh's points all coincide");

  faces_ = mesh.faces;
  const Eigen::Matrix3d rotation = world_from_mesh.rotation.toRotationMatrix();
  normals_.resize(n);
  for (size_t i = 0; i < n; ++i) {
    const Eigen::Vector3d normal = rotation * mesh.normals[i];
    const double length = normal.norm();
    normals_[i] = length > 1e-12 ? Eigen::Vector3d(normal / length) : Eigen::Vector3d::Zero();
  }
  if (!mesh.fit_rms_m.empty()) {
    fit_rms_m_.resize(n);
    for (size_t i = 0; i < n; ++i) fit_rms_m_[i] = float(mesh.fit_rms_m[i] * world_from_mesh.scale);
  }
  fit_neighbours_ = mesh.fit_neighbours;

  embree_ = std::make_unique<Embree>(source);
  RTCDevice device = embree_->scene.device;
  RTCGeometry geometry = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
  auto* vertices = static_cast<float*>(
      rtcSetNewGeometryBuffer(geometry, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), n));
  auto* indices = static_cast<unsigned*>(rtcSetNewGeometryBuffer(geometry, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                                                 3 * sizeof(unsigned), faces_.size()));
  if (!vertices || !indices) {
    rtcReleaseGeometry(geometry);
    ThrowError(source, "cannot allocate the ray-tracing buffers: " + embree_->scene.errors.first);
  }
  for (size_t i = 0; i < n; ++i) {
    for (int k = 0; k < 3; ++k) vertices[3 * i + k] = float(points_[i][k]);
  }
  for (size_t f = 0; f < faces_.size(); ++f) {
    for (int k = 0; k < 3; ++k) indices[3 * f + k] = unsigned(faces_[f][k]);
  }
  rtcSetGeometryBuildQuality(geometry, RTC_BUILD_QUALITY_HIGH);
  rtcCommitGeometry(geometry);
  rtcAttachGeometry(embree_->scene.scene, geometry);
  rtcReleaseGeometry(geometry);
  embree_->scene.Commit(source);
}

MeshSample::~MeshSample() = default;

bool MeshSample::RefineHit(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction, unsigned face,
                           float t_float, float u_float, float v_float, double* t_out, double* u_out,
                           double* v_out) const {
  const Eigen::Vector3i& f = faces_[face];
  const Eigen::Vector3d& p0 = points_[f[0]];
  const Eigen::Vector3d& p1 = points_[f[1]];
  const Eigen::Vector3d& p2 = points_[f[2]];
  const Eigen::Vector3d o = origin - origin_;  // local, double
  const Eigen::Vector3d e1 = p1 - p0, e2 = p2 - p0;
  // Moeller-Trumbore in double on the face Embree found: t, u, v to double precision. A ray (nearly)
  // in the face's plane has no well-defined double answer; Embree's float one is kept then.
  double t = t_float, u = u_float, v = v_float;
  const Eigen::Vector3d pvec = direction.cross(e2);
  const double det = e1.dot(pvec);
  const double scale = e1.norm() * e2.norm();
  if (std::abs(det) > 1e-12 * scale) {
    const double inv = 1.0 / det;
    const Eigen::Vector3d s = o - p0;
    const Eigen::Vector3d q = s.cross(e1);
    const double t_double = e2.dot(q) * inv;
    const double u_double = s.dot(pvec) * inv;
    const double v_double = direction.dot(q) * inv;
    if (std::isfinite(t_double) && std::isfinite(u_double) && std::isfinite(v_double) && t_double > 0.0) {
      t = t_double;
      u = u_double;
      v = v_double;
    }
  }
  *t_out = t;
  *u_out = u;
  *v_out = v;
  return t > 0.0 && std::isfinite(t);
}

bool MeshSample::CompleteHit(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction, unsigned face,
                             float t_float, float u_float, float v_float, SurfaceHit* hit) const {
  double t, u, v;
  if (!RefineHit(origin, direction, face, t_float, u_float, v_float, &t, &u, &v)) return false;
  const Eigen::Vector3i& f = faces_[face];
  const Eigen::Vector3d e1 = points_[f[1]] - points_[f[0]], e2 = points_[f[2]] - points_[f[0]];
  // Embree's robust test may accept a hit a rounding error outside the face: clamp to it.
  u = std::clamp(u, 0.0, 1.0);
  v = std::clamp(v, 0.0, 1.0 - u);
  const double w = 1.0 - u - v;
  hit->t = t;
  hit->point = origin + t * direction;
  hit->face = int(face);
  const Eigen::Vector3d normal = w * normals_[f[0]] + u * normals_[f[1]] + v * normals_[f[2]];
  const double length = normal.norm();
  hit->normal = length > 1e-6 ? Eigen::Vector3d(normal / length) : Eigen::Vector3d::Zero();
  const Eigen::Vector3d geometric = e1.cross(e2);
  const double area2 = geometric.norm();
  hit->geometric_normal = area2 > 0.0 ? Eigen::Vector3d(geometric / area2) : Eigen::Vector3d::Zero();
  if (!fit_rms_m_.empty()) {
    hit->fit_rms_m = float(w * fit_rms_m_[f[0]] + u * fit_rms_m_[f[1]] + v * fit_rms_m_[f[2]]);
  }
  if (!fit_neighbours_.empty()) {
    hit->fit_neighbours = std::min({fit_neighbours_[f[0]], fit_neighbours_[f[1]], fit_neighbours_[f[2]]});
  }
  return true;
}

bool MeshSample::Intersect(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction, SurfaceHit* hit) const {
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  RTCRayHit rayhit;
  InitRayHit((origin - origin_).cast<float>(), direction.cast<float>(), &rayhit);
  rtcIntersect1(embree_->scene.scene, &context, &rayhit);
  if (rayhit.hit.geomID == RTC_INVALID_GEOMETRY_ID) return false;
  return CompleteHit(origin, direction, rayhit.hit.primID, rayhit.ray.tfar, rayhit.hit.u, rayhit.hit.v, hit);
}

template <class OnHit, class OnMiss>
void MeshSample::CastBatch(const Eigen::Vector3d& origin, const Eigen::Vector3d* directions, size_t count, OnHit on_hit,
                           OnMiss on_miss) const {
  const Eigen::Vector3f o = (origin - origin_).cast<float>();
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  switch (ray_mode_) {
    case RayMode::kSingle:
      for (size_t i = 0; i < count; ++i) {
        RTCRayHit rayhit;
        InitRayHit(o, directions[i].cast<float>(), &rayhit);
        rtcIntersect1(embree_->scene.scene, &context, &rayhit);
        if (rayhit.hit.geomID == RTC_INVALID_GEOMETRY_ID) {
          on_miss(i);
        } else {
          on_hit(i, rayhit.hit.primID, rayhit.ray.tfar, rayhit.hit.u, rayhit.hit.v);
        }
      }
      return;
    case RayMode::kPacket8: {
      context.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
      alignas(32) int valid[8];
      alignas(32) RTCRayHit8 packet;
      for (size_t begin = 0; begin < count; begin += 8) {
        const size_t lanes = std::min<size_t>(8, count - begin);
        for (size_t k = 0; k < 8; ++k) {
          const bool active = k < lanes;
          valid[k] = active ? -1 : 0;
          const Eigen::Vector3f d =
              active ? Eigen::Vector3f(directions[begin + k].cast<float>()) : Eigen::Vector3f(Eigen::Vector3f::UnitZ());
          packet.ray.org_x[k] = o.x();
          packet.ray.org_y[k] = o.y();
          packet.ray.org_z[k] = o.z();
          packet.ray.dir_x[k] = d.x();
          packet.ray.dir_y[k] = d.y();
          packet.ray.dir_z[k] = d.z();
          packet.ray.tnear[k] = 0.0f;
          packet.ray.tfar[k] = std::numeric_limits<float>::infinity();
          packet.ray.time[k] = 0.0f;
          packet.ray.mask[k] = 0xFFFFFFFFu;
          packet.ray.id[k] = unsigned(k);
          packet.ray.flags[k] = 0;
          packet.hit.geomID[k] = RTC_INVALID_GEOMETRY_ID;
          packet.hit.instID[0][k] = RTC_INVALID_GEOMETRY_ID;
        }
        rtcIntersect8(valid, embree_->scene.scene, &context, &packet);
        for (size_t k = 0; k < lanes; ++k) {
          if (packet.hit.geomID[k] == RTC_INVALID_GEOMETRY_ID) {
            on_miss(begin + k);
          } else {
            on_hit(begin + k, packet.hit.primID[k], packet.ray.tfar[k], packet.hit.u[k], packet.hit.v[k]);
          }
        }
      }
      return;
    }
    case RayMode::kStream: {
      context.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
      std::vector<RTCRayHit> stream(count);
      for (size_t i = 0; i < count; ++i) InitRayHit(o, directions[i].cast<float>(), &stream[i]);
      rtcIntersect1M(embree_->scene.scene, &context, stream.data(), unsigned(count), sizeof(RTCRayHit));
      for (size_t i = 0; i < count; ++i) {
        if (stream[i].hit.geomID == RTC_INVALID_GEOMETRY_ID) {
          on_miss(i);
        } else {
          on_hit(i, stream[i].hit.primID, stream[i].ray.tfar, stream[i].hit.u, stream[i].hit.v);
        }
      }
      return;
    }
  }
}

void MeshSample::IntersectBatch(const Eigen::Vector3d& origin, const Eigen::Vector3d* directions, size_t count,
                                SurfaceHit* hits, bool* found) const {
  CastBatch(
      origin, directions, count,
      [&](size_t i, unsigned face, float t, float u, float v) {
        found[i] = CompleteHit(origin, directions[i], face, t, u, v, &hits[i]);
      },
      [&](size_t i) { found[i] = false; });
}

void MeshSample::DepthBatch(const Eigen::Vector3d& origin, const Eigen::Vector3d* directions, size_t count,
                            double* depths) const {
  constexpr double kMiss = std::numeric_limits<double>::quiet_NaN();
  CastBatch(
      origin, directions, count,
      [&](size_t i, unsigned face, float t_float, float u_float, float v_float) {
        double t, u, v;
        depths[i] = RefineHit(origin, directions[i], face, t_float, u_float, v_float, &t, &u, &v) ? t : kMiss;
      },
      [&](size_t i) { depths[i] = kMiss; });
}

bool MeshSample::Contains(const Eigen::Vector3d& point) const {
  for (int axis = 0; axis < 3; ++axis) {
    for (double sign : {-1.0, 1.0}) {
      const Eigen::Vector3d direction = sign * Eigen::Vector3d::Unit(axis);
      SurfaceHit hit;
      if (!Intersect(point, direction, &hit)) return false;
      if (!(hit.geometric_normal.dot(direction) > 0.0)) return false;  // leaves through a front face: outside
    }
  }
  return true;
}

bool MeshSample::Occluded(const Eigen::Vector3d& from, const Eigen::Vector3d& to) const {
  const Eigen::Vector3d offset = to - from;
  const double length = offset.norm();
  const double epsilon = Epsilon();
  if (!(length > 2.0 * epsilon)) return false;
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  RTCRay ray;
  InitRay((from - origin_).cast<float>(), (offset / length).cast<float>(), float(epsilon), float(length - epsilon),
          &ray);
  rtcOccluded1(embree_->scene.scene, &context, &ray);
  return ray.tfar < 0.0f;  // Embree sets tfar to -inf for an occluded ray
}

QuadOccluders::QuadOccluders(const std::vector<std::array<Eigen::Vector3d, 4>>& quads) {
  std::vector<std::array<Eigen::Vector3d, 4>> kept;
  for (const auto& quad : quads) {
    bool finite = true;
    for (const Eigen::Vector3d& c : quad) finite &= c.allFinite();
    if (!finite) continue;
    const double area2 = (quad[2] - quad[0]).cross(quad[3] - quad[1]).norm();
    if (area2 > 0.0) kept.push_back(quad);
  }
  num_quads_ = kept.size();
  if (kept.empty()) return;
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (const auto& quad : kept) sum += quad[0] - kept[0][0];
  origin_ = kept[0][0] + sum / double(kept.size());
  const std::string source = "reference markers";
  embree_ = std::make_unique<Embree>(source);
  RTCGeometry geometry = rtcNewGeometry(embree_->scene.device, RTC_GEOMETRY_TYPE_QUAD);
  auto* vertices = static_cast<float*>(rtcSetNewGeometryBuffer(geometry, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                                               3 * sizeof(float), 4 * kept.size()));
  auto* indices = static_cast<unsigned*>(
      rtcSetNewGeometryBuffer(geometry, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT4, 4 * sizeof(unsigned), kept.size()));
  if (!vertices || !indices) {
    rtcReleaseGeometry(geometry);
    ThrowError(source, "cannot allocate the ray-tracing buffers: " + embree_->scene.errors.first);
  }
  for (size_t q = 0; q < kept.size(); ++q) {
    for (int c = 0; c < 4; ++c) {
      const Eigen::Vector3d local = kept[q][c] - origin_;
      for (int k = 0; k < 3; ++k) vertices[3 * (4 * q + c) + k] = float(local[k]);
      indices[4 * q + c] = unsigned(4 * q + c);
    }
  }
  rtcCommitGeometry(geometry);
  rtcAttachGeometry(embree_->scene.scene, geometry);
  rtcReleaseGeometry(geometry);
  embree_->scene.Commit(source);
}

QuadOccluders::~QuadOccluders() = default;

bool QuadOccluders::Blocks(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction, double max_t) const {
  if (num_quads_ == 0 || !(max_t > 0.0)) return false;
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  RTCRay ray;
  InitRay((origin - origin_).cast<float>(), direction.cast<float>(), 0.0f, float(max_t), &ray);
  rtcOccluded1(embree_->scene.scene, &context, &ray);
  return ray.tfar < 0.0f;
}

}  // namespace ibrdf
