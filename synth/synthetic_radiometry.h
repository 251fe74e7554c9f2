// The radiometric side of synthetic sessions (docs/radiometry.md): the sensor (shot and read noise,
// black level, clipping, response, quantization), vignetting and its flat-field image, exposure
// brackets, and the white-reference photo that calibrates an unknown light. Called from
// WriteSyntheticSession (synth/synthetic.cc) at a few marked hooks; the options are
// SynthRadiometryOptions and CameraEffects (synth/synth_options.h).
#pragma once

#include <cstdint>
#include <functional>
#include <string>

#include <Eigen/Core>

#include "core/camera.h"
#include "core/image_io.h"
#include "core/rigid3.h"
#include "core/session.h"
#include "synth/synth_options.h"

namespace ibrdf {

// Relative sensitivity of a pixel (col + 0.5, row + 0.5 at its centre) under natural vignetting of
// the given strength: cos^4 of an effective field angle that grows with the distance r from the
// principal point, 1 / (1 + r^2 tan^2(a))^2 with r = 1 at the farthest image corner and a chosen so
// that the corner keeps 1 - strength. Strength 0: 1 everywhere.
double VignettingAt(const Camera& camera, double strength, double x, double y);

// The toe-and-shoulder curve (SensorCurve::kToeShoulder): file = (1 + k) x^a / (x^a + k) with a = 1.6,
// k = 0.25 (a Naka-Rushton curve, the shape of film's and of a JPEG camera's tone curve in log
// exposure): 0 at 0 and 1 at 1, a toe (slope 0 at black) and a shoulder (slope 0.32 at full scale).
// Decode is its exact inverse.
double ToeShoulderEncode(double linear);
double ToeShoulderDecode(double encoded);

// A signal in [0, 1] through the sensor's curve.
double EncodeSensorCurve(SensorCurve curve, double linear);

// Multiplies a linear signal image by the vignetting of the given strength (nothing for 0).
void ApplyVignetting(const Camera& camera, double strength, Image* signal);

// The sensor: shot noise (Poisson below 1000 electrons, Gaussian above), read noise, black level,
// clipping at 1.0, the sRGB curve, quantization to `bits`, applied in place to a linear signal image.
// One random stream per (seed, stream, row): the output does not depend on the thread count. Returns
// the number of pixels with a clipped channel.
uint64_t SimulateSensor(const CameraEffects& effects, uint64_t seed, uint64_t stream, Image* signal);

// Hook in BuildSession: each measurement photo becomes options.radiometry.brackets photos of its pose
// ("photos/003-e1.png"), with `bracket` = the pose's index and exposure_s holding the bracket's factor
// (1, 2^-step, ...) that the auto-exposure multiplies. Nothing for 1 bracket.
void ExpandBrackets(const SynthOptions& options, Session* session);

// Whether a ray (origin, unit direction) hits something nearer than `t` (metres along it).
using TargetOccluder = std::function<bool(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction, double t)>;
// Adds the session's coded targets (the platform) to a linear signal image taken from
// `camera_from_world`, where `in_front` does not hide them.
using TargetCompositor =
    std::function<void(const Rigid3d& camera_from_world, const TargetOccluder& in_front, Image* signal)>;

// Hook before the session is saved, in the folder being written (`directory`): writes the flat-field
// image (flat_field.exr, when vignetting is on) and the white-reference photo (light_unknown), adds
// them to the session, and replaces the light's intensity by (1, 1, 1) when it is to be unknown. With
// targets.white_card the white reference is the marker card, raised to clear the platform, and
// `composite_targets` (may be empty) adds the platform behind it to each white-reference photo.
void WriteSynthCalibration(const SynthOptions& options, const std::string& directory, Session* session,
                           const TargetCompositor& composite_targets = TargetCompositor());

}  // namespace ibrdf
