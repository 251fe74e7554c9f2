// The cylinder's pose from the markers fixed to it: a cylinder fitted to the 3D target
// corners along its edges. The session states each sample marker's corners in the cylinder's own
// frame (origin at its centre, z along its axis; docs/session-format.md, targets.sample); the bundle
// adjustment gives their world corners; the rigid transform between the two (Umeyama's closed form,
// then Ceres with a Cauchy loss, markers that disagree left out) places the cylinder: its centre is
// the frame's origin, its axis the frame's z. The radius and length stay as given (measured).
#pragma once

#include <map>
#include <string>

#include <Eigen/Core>

#include "align/bundle_adjustment.h"
#include "core/rigid3.h"
#include "core/session.h"

namespace ibrdf {

struct CylinderFitOptions {
  int min_markers = 2;             // fewer posed sample markers: no fit (the sample stays as given)
  double cauchy_m = 2e-4;          // robust loss scale on corner distances, metres
  double max_marker_rms_m = 1e-3;  // a marker whose corners miss by more (RMS) is left out
  bool Check(std::string* why) const;
};

struct CylinderFit {
  bool fitted = false;
  std::string reason;  // why not fitted
  Rigid3d world_from_sample;
  Eigen::Vector3d center = Eigen::Vector3d::Zero();
  Eigen::Vector3d axis = Eigen::Vector3d::UnitZ();  // unit, the given axis' sense
  int markers = 0;                                  // sample markers used
  int rejected_markers = 0;                         // posed but left out (their corners disagree)
  double rms_m = 0.0;                               // corner distance RMS after the fit, metres
  std::string BriefReport() const;
};

// Fits the sample's pose to the posed sample markers among `markers` (ids of spec.markers). Too few
// posed markers, a failed solve or markers that disagree: not fitted, with the reason. Throws Error
// for bad options.
CylinderFit FitCylinderToMarkers(const SampleTargetsSpec& spec, const std::map<int, BundleMarker>& markers,
                                 const SampleSpec& given, const CylinderFitOptions& options);

}  // namespace ibrdf
