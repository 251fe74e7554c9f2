#include "reconstruct/prediction_check.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <random>

#include <nlohmann/json.hpp>

#include "core/brdf_coords.h"
#include "core/error.h"
#include "core/logging.h"
#include "core/math.h"
#include "core/statistics.h"

namespace ibrdf {
namespace {

Eigen::Vector3d Coordinates(double theta_i, double theta_e, double delta_phi) {
  Eigen::Vector3d wi, wo;
  FromIsotropic({theta_i, theta_e, delta_phi}, &wi, &wo);
  return RegressionCoordinates(wi, wo);
}

// Compares the regression at point pairs (a[i], b[i]); pairs where either estimate is not a full fit
// with enough samples are left out.
PairFigure ComparePairs(const LocalRegression& regression, const std::vector<Eigen::Vector3d>& a,
                        const std::vector<Eigen::Vector3d>& b, float min_effective_samples) {
  const std::vector<Estimate> ea = regression.EvaluateMany(a, nullptr);
  const std::vector<Estimate> eb = regression.EvaluateMany(b, nullptr);
  PairFigure figure;
  std::vector<double> errors;
  for (size_t i = 0; i < a.size(); ++i) {
    const Estimate& x = ea[i];
    const Estimate& y = eb[i];
    if (x.status != EstimateStatus::kFull || y.status != EstimateStatus::kFull) continue;
    if (x.effective_samples < min_effective_samples || y.effective_samples < min_effective_samples) continue;
    Eigen::Vector3d rel;
    for (int c = 0; c < 3; ++c) {
      const double mean = 0.5 * (x.value[c] + y.value[c]);
      rel[c] = mean > 0.0 ? std::abs(x.value[c] - y.value[c]) / mean : 0.0;
    }
    figure.mean_rel_error += rel;
    errors.push_back(rel.mean());
  }
  figure.pairs = errors.size();
  if (figure.pairs > 0) {
    figure.mean_rel_error /= double(figure.pairs);
    figure.mean = figure.mean_rel_error.mean();
    figure.median = Percentile(errors, 0.5);
    figure.p95 = Percentile(errors, 0.95);
  }
  return figure;
}

nlohmann::json Rgb(const Eigen::Vector3d& v) { return nlohmann::json::array({v[0], v[1], v[2]}); }

// An invalid figure (no pairs) has null values, not 0.
nlohmann::json FigureJson(const PairFigure& figure) {
  const auto value = [&](const nlohmann::json& v) { return figure.valid() ? v : nlohmann::json(); };
  return {{"valid", figure.valid()},
          {"pairs", figure.pairs},
          {"mean_rel_error", value(figure.mean)},
          {"per_channel_rel_error", value(Rgb(figure.mean_rel_error))},
          {"median_rel_error", value(figure.median)},
          {"p95_rel_error", value(figure.p95)}};
}

}  // namespace

bool PredictionCheckOptions::Check(std::string* why) const {
  if (!regression.Check(why)) return false;
  IBRDF_CHECK_OPTION_GE(held_out_photos, 0);
  IBRDF_CHECK_OPTION_GE(max_predicted_samples, size_t(1));
  IBRDF_CHECK_OPTION_GT(max_theta_deg, 0.0);
  IBRDF_CHECK_OPTION_LE(max_theta_deg, 90.0);
  IBRDF_CHECK_OPTION_GE(near_plane_deg, 0.0);
  IBRDF_CHECK_OPTION_LT(near_plane_deg, 90.0);
  IBRDF_CHECK_OPTION_GT(step_deg, 0.0);
  return true;
}

std::vector<uint32_t> HeldOutImages(const std::vector<BrdfSample>& samples, int count) {
  std::map<uint32_t, size_t> per_image;
  for (const BrdfSample& s : samples) ++per_image[s.image];
  std::vector<uint32_t> images;
  for (const auto& [image, n] : per_image) images.push_back(image);
  const int held = std::min<int>(std::max(count, 0), images.size() > 1 ? int(images.size()) : 0);
  std::vector<uint32_t> held_out;
  for (int h = 0; h < held; ++h) held_out.push_back(images[(2 * h + 1) * images.size() / (2 * held)]);
  return held_out;
}

PredictionReport CheckWithRegression(const std::vector<BrdfSample>& samples, const PredictionCheckOptions& options) {
  std::string why;
  if (!options.Check(&why)) ThrowError("check options", why);
  Timer timer;
  PredictionReport report;

  // Symmetries: an unfolded regression, so nothing is assumed.
  {
    LocalRegressionOptions unfolded = options.regression;
    unfolded.fold_reciprocity = false;
    unfolded.fold_bilateral = false;
    const LocalRegression regression(samples, unfolded);
    const double step = options.step_deg * kDegree, limit = options.max_theta_deg * kDegree + 1e-9;
    std::vector<Eigen::Vector3d> a, b;
    // Reciprocity: fixed incidence t0 against fixed exitance t0, near the plane on both sides.
    std::vector<double> phis;
    for (double d = 0.0; d <= options.near_plane_deg + 1e-9; d += options.step_deg) {
      for (double phi : {d, -d, 180.0 - d, -(180.0 - d)}) {
        if (std::find(phis.begin(), phis.end(), phi) == phis.end() && phi > -180.0) phis.push_back(phi);
      }
    }
    for (double t0 = step; t0 <= limit; t0 += step) {
      for (double t = step; t <= limit; t += step) {
        if (std::abs(t - t0) < 1e-9) continue;
        for (double phi_deg : phis) {
          a.push_back(Coordinates(t0, t, phi_deg * kDegree));
          b.push_back(Coordinates(t, t0, -phi_deg * kDegree));
        }
      }
    }
    report.reciprocity = ComparePairs(regression, a, b, options.min_effective_samples);
    a.clear();
    b.clear();
    for (double ti = step; ti <= limit; ti += step) {
      for (double te = step; te <= limit; te += step) {
        for (double phi = options.step_deg; phi < 180.0 - 1e-9; phi += 2.0 * options.step_deg) {
          a.push_back(Coordinates(ti, te, phi * kDegree));
          b.push_back(Coordinates(ti, te, -phi * kDegree));
        }
      }
    }
    report.bilateral = ComparePairs(regression, a, b, options.min_effective_samples);
  }

  // Held-out photos, evenly spaced over the images present.
  double sum_squares[3] = {0, 0, 0};
  for (const uint32_t image : HeldOutImages(samples, options.held_out_photos)) {
    std::vector<BrdfSample> fit, predict;
    for (const BrdfSample& s : samples) (s.image == image ? predict : fit).push_back(s);
    const double max_theta = options.max_theta_deg * kDegree;
    const size_t in_photo = predict.size();
    predict.erase(std::remove_if(predict.begin(), predict.end(),
                                 [&](const BrdfSample& s) { return s.theta_i > max_theta || s.theta_e > max_theta; }),
                  predict.end());
    HeldOutPhoto photo;
    photo.image = image;
    if (predict.empty()) {
      char note[160];
      std::snprintf(note, sizeof(note), "none of its %zu samples has theta_i and theta_e below %g deg", in_photo,
                    options.max_theta_deg);
      photo.note = note;
      report.held_out.push_back(photo);
      continue;
    }
    if (predict.size() > options.max_predicted_samples) {
      std::mt19937_64 rng(image + 1);
      std::shuffle(predict.begin(), predict.end(), rng);
      predict.resize(options.max_predicted_samples);
    }
    const LocalRegression regression(fit, options.regression);
    std::vector<Eigen::Vector3d> points;
    for (const BrdfSample& s : predict) {
      points.push_back(RegressionCoordinates(Eigen::Vector3d(s.wi[0], s.wi[1], s.wi[2]).normalized(),
                                             Eigen::Vector3d(s.wo[0], s.wo[1], s.wo[2]).normalized()));
    }
    const std::vector<Estimate> estimates = regression.EvaluateMany(points, &photo.reliability);
    std::vector<double> abs_rel[3];
    size_t within = 0, with_sigma = 0;
    for (size_t i = 0; i < predict.size(); ++i) {
      for (int c = 0; c < 3; ++c) {
        if (!predict[i].Valid(c)) continue;  // a channel the photo did not measure (clipped, under the floor)
        const double f = predict[i].brdf[c];
        const double rel = (estimates[i].value[c] - f) / std::max(std::abs(f), 1e-6);
        photo.rms_rel_error[c] += rel * rel;
        sum_squares[c] += rel * rel;
        abs_rel[c].push_back(std::abs(rel));
        ++photo.measured[c];
        if (predict[i].sigma[c] > 0.0f) {
          ++with_sigma;
          within += std::abs(estimates[i].value[c] - f) <= 2.0 * predict[i].sigma[c];
        }
      }
    }
    photo.predicted = predict.size();
    for (int c = 0; c < 3; ++c) {
      if (photo.measured[c] == 0) continue;
      photo.rms_rel_error[c] = std::sqrt(photo.rms_rel_error[c] / photo.measured[c]);
      photo.median_rel_error[c] = Percentile(abs_rel[c], 0.5);
      report.held_out_measured[c] += photo.measured[c];
    }
    if (!photo.valid()) photo.note = "no channel of its predicted samples was measured";
    if (with_sigma > 0) photo.within_2_sigma = double(within) / with_sigma;
    report.held_out.push_back(photo);
  }
  for (int c = 0; c < 3; ++c) {
    const size_t n = report.held_out_measured[c];
    report.held_out_rms[c] = n ? std::sqrt(sum_squares[c] / n) : 0.0;
  }
  report.seconds = timer.ElapsedSeconds();
  report.success = true;
  return report;
}

std::string HeldOutHeadline(const PredictionReport& report) {
  if (report.held_out.empty()) return "no held-out photos";
  std::string line = std::to_string(report.held_out.size()) + " held-out photos";
  if (!report.held_out_valid()) {
    return line + ", nothing predicted (none of their samples lies below max_theta_deg with a measured channel)";
  }
  line += ", RMS prediction error R G B";
  for (int c = 0; c < 3; ++c) {
    char value[32];
    std::snprintf(value, sizeof(value), " %.2f", 100.0 * report.held_out_rms[c]);
    line += report.held_out_measured[c] ? value : " n/a";
  }
  line += " %";
  for (const HeldOutPhoto& photo : report.held_out) {
    if (!photo.valid()) line += "; photo " + std::to_string(photo.image) + " not predicted: " + photo.note;
  }
  return line;
}

std::string PredictionReport::BriefReport() const {
  auto figure = [](const PairFigure& f) {
    char buffer[96];
    if (!f.valid()) return std::string("invalid (no pair had two estimates)");
    std::snprintf(buffer, sizeof(buffer), "%.2f %% over %zu pairs", 100.0 * f.mean, f.pairs);
    return std::string(buffer);
  };
  return "regression check: reciprocity near the incidence plane " + figure(reciprocity) + "; bilateral " +
         figure(bilateral) + "; " + HeldOutHeadline(*this);
}

nlohmann::json ToJson(const PredictionReport& report, const PredictionCheckOptions& options) {
  nlohmann::json photos = nlohmann::json::array();
  // A channel without measured predictions has no figure: null, not 0.
  auto rgb_or_null = [](const Eigen::Vector3d& v, const Eigen::Matrix<size_t, 3, 1>& n) {
    nlohmann::json out = nlohmann::json::array();
    for (int c = 0; c < 3; ++c) out.push_back(n[c] ? nlohmann::json(v[c]) : nlohmann::json());
    return out;
  };
  for (const HeldOutPhoto& p : report.held_out) {
    nlohmann::json photo = {
        {"image", p.image},
        {"valid", p.valid()},
        {"predicted_samples", p.predicted},
        {"measured_values", {p.measured[0], p.measured[1], p.measured[2]}},
        {"rms_rel_error", rgb_or_null(p.rms_rel_error, p.measured)},
        {"median_rel_error", rgb_or_null(p.median_rel_error, p.measured)},
        {"within_2_sigma", p.within_2_sigma >= 0.0 ? nlohmann::json(p.within_2_sigma) : nlohmann::json()},
        {"reliability", ToJson(p.reliability)}};
    if (!p.note.empty()) photo["note"] = p.note;
    photos.push_back(photo);
  }
  const LocalRegressionOptions& r = options.regression;
  return {{"method",
           "local regression (unfolded) compared at point pairs; held-out photos predicted by a fit "
           "without them"},
          {"options",
           {{"degree", r.degree},
            {"radius_h_deg", r.radius_h_deg},
            {"radius_d_deg", r.radius_d_deg},
            {"held_out_photos", options.held_out_photos},
            {"max_theta_deg", options.max_theta_deg},
            {"near_plane_deg", options.near_plane_deg},
            {"step_deg", options.step_deg},
            {"min_effective_samples", options.min_effective_samples}}},
          {"reciprocity_near_incidence_plane", FigureJson(report.reciprocity)},
          {"bilateral_symmetry", FigureJson(report.bilateral)},
          {"held_out_photos", photos},
          {"held_out_valid", report.held_out_valid()},
          {"held_out_rms_rel_error", rgb_or_null(report.held_out_rms, report.held_out_measured)},
          {"seconds", report.seconds}};
}

}  // namespace ibrdf
