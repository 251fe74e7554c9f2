// The scanned sample (the paper's section 3.1 for irregular objects): pixel rays intersect the
// tessellated scan, and the normal at a hit is interpolated from the per-point local-plane normals of
// the scan stage rather than taken from the faces, to keep scanner noise out of the BRDF.
//
// Ray casting is Embree 3's (a robust, high-quality BVH over the triangles). Embree works in float, so
// the vertices are stored relative to a double-precision local origin (the centroid of the mesh in
// the world): rays are built in double in the world frame, shifted by the origin and cast in float,
// and every hit is recomputed in double from the hit triangle's double vertices. A scan 10 km from
// the origin keeps its sub-micrometre detail. Embree types stay in mesh_sample.cc.
#pragma once

#include <array>
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "core/rigid3.h"
#include "derender/analytic_sample.h"
#include "scan/scan_mesh.h"

namespace ibrdf {

class MeshSample : public SampleSurface {
 public:
  // How batches of rays are handed to Embree (all give the same hits; docs/benchmarks.md compares
  // their speed).
  enum class RayMode {
    kSingle,   // rtcIntersect1 per ray
    kPacket8,  // rtcIntersect8: packets of 8 neighbouring pixels
    kStream,   // rtcIntersect1M: the whole batch as one coherent stream
  };

  // Builds the scene from a mesh in its own frame, placed in the world by `world_from_mesh`. Throws
  // Error naming `source` for a mesh without faces, without per-point normals, or with per-point data
  // of the wrong length, and for Embree failures.
  MeshSample(const ScanMesh& mesh, const Sim3d& world_from_mesh, const std::string& source);
  ~MeshSample() override;
  MeshSample(const MeshSample&) = delete;
  MeshSample& operator=(const MeshSample&) = delete;

  // The nearest hit (rtcIntersect1), recomputed in double: t, point, the barycentric interpolation
  // of the per-point normals (unit; zero where they cancel), the face's normal, the fit quality.
  bool Intersect(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction, SurfaceHit* hit) const override;
  // Rays sharing one origin (a camera centre), e.g. a row of pixels: found[i] tells whether
  // directions[i] hit, hits[i] what it hit. Same results as Intersect, faster in kPacket8/kStream.
  void IntersectBatch(const Eigen::Vector3d& origin, const Eigen::Vector3d* directions, size_t count, SurfaceHit* hits,
                      bool* found) const;
  // The distance of each ray's hit alone, as IntersectBatch would report it in SurfaceHit::t (NaN where
  // the ray misses): for rays whose depth is all that is needed (the mixed-pixel test's pixel corners).
  void DepthBatch(const Eigen::Vector3d& origin, const Eigen::Vector3d* directions, size_t count, double* depths) const;
  // Inside when rays along all six axis directions leave through back faces (exact for a closed
  // mesh; an open scan has no inside and gives false almost everywhere).
  bool Contains(const Eigen::Vector3d& point) const override;
  Eigen::Vector3d BoundingCenter() const override { return bounding_center_; }
  double BoundingRadius() const override { return bounding_radius_; }
  // A shadow ray (rtcOccluded1): the segment from `from` to `to` with both ends shortened by
  // Epsilon(), so the surface a ray starts on does not block it.
  bool Occluded(const Eigen::Vector3d& from, const Eigen::Vector3d& to) const override;

  // Self-intersection margin for shadow rays: 1e-6 of the bounding radius (float keeps about 1e-7
  // relative in local coordinates), metres.
  double Epsilon() const { return 1e-6 * bounding_radius_; }
  const Eigen::Vector3d& local_origin() const { return origin_; }
  size_t NumFaces() const { return faces_.size(); }
  size_t NumPoints() const { return points_.size(); }
  // True when the mesh carries fit_rms_m and fit_neighbours (the scan stage writes both).
  bool HasFitQuality() const { return !fit_rms_m_.empty() && !fit_neighbours_.empty(); }

  void set_ray_mode(RayMode mode) { ray_mode_ = mode; }
  RayMode ray_mode() const { return ray_mode_; }

 private:
  struct Embree;
  // Fills `hit` from the face Embree reported and its float (t, u, v); false if the double
  // recomputation finds nothing usable.
  bool CompleteHit(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction, unsigned face, float t, float u,
                   float v, SurfaceHit* hit) const;
  // CompleteHit's first half: t, u and v recomputed in double (not yet clamped to the face); false
  // where no positive finite t remains.
  bool RefineHit(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction, unsigned face, float t_float,
                 float u_float, float v_float, double* t, double* u, double* v) const;
  // Casts the rays (IntersectBatch's modes) and calls on_hit(i, face, t, u, v) for each ray Embree hits
  // (in order of i within each packet), on_miss(i) for the others.
  template <class OnHit, class OnMiss>
  void CastBatch(const Eigen::Vector3d& origin, const Eigen::Vector3d* directions, size_t count, OnHit on_hit,
                 OnMiss on_miss) const;

  Eigen::Vector3d origin_;               // world; the local frame's origin
  std::vector<Eigen::Vector3d> points_;  // world - origin_, double
  std::vector<Eigen::Vector3i> faces_;
  std::vector<Eigen::Vector3d> normals_;  // world orientation, unit or zero
  std::vector<float> fit_rms_m_;          // world units (scaled)
  std::vector<int> fit_neighbours_;
  Eigen::Vector3d bounding_center_;
  double bounding_radius_ = 0.0;
  RayMode ray_mode_ = RayMode::kPacket8;
  std::unique_ptr<Embree> embree_;
};

// Planar quads that can hide the sample from a camera (the reference markers of known layout), in
// their own Embree scene: a pixel whose ray meets one before the sample is masked.
class QuadOccluders {
 public:
  // Quads given by 4 world corners in order around the quad; degenerate ones are left out.
  explicit QuadOccluders(const std::vector<std::array<Eigen::Vector3d, 4>>& quads);
  ~QuadOccluders();
  QuadOccluders(const QuadOccluders&) = delete;
  QuadOccluders& operator=(const QuadOccluders&) = delete;

  // True if the ray origin + t * direction (unit) meets a quad with 0 < t < max_t.
  bool Blocks(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction, double max_t) const;
  size_t NumQuads() const { return num_quads_; }

 private:
  struct Embree;
  Eigen::Vector3d origin_ = Eigen::Vector3d::Zero();
  size_t num_quads_ = 0;
  std::unique_ptr<Embree> embree_;
};

}  // namespace ibrdf
