// The report's one-line summaries (report/report_stage.h) never print "nan": a run whose
// reconstruction has no brdf.binary, a held-out photo with nothing to compare, an incidence-plane band
// without samples (an all -1 table) each say so in words.
#include <cmath>
#include <string>

#include <gtest/gtest.h>

#include "report/report_stage.h"

namespace ibrdf {
namespace {

TEST(ReportBrief, HeldOutPhotoWithoutReconstructionSaysSo) {
  ReportResult result;
  result.success = true;
  HeldOutRender h;
  h.image = 9;
  h.median_abs_difference = 0.031;
  result.held_out.push_back(h);  // in_sample_median_abs_difference stays NaN: no brdf.binary
  const std::string line = result.BriefReport();
  EXPECT_EQ(line.find("nan"), std::string::npos) << line;
  EXPECT_NE(line.find("3.1 %"), std::string::npos) << line;
  EXPECT_NE(line.find("no brdf.binary"), std::string::npos) << line;
  result.held_out[0].median_abs_difference = NAN;
  EXPECT_EQ(result.BriefReport().find("nan"), std::string::npos) << result.BriefReport();
}

TEST(ReportBrief, BandWithoutSamplesSaysSo) {
  for (const double theta0 : {0.0, 30.0, 45.0, 60.0}) {
    BandAgreement band;
    band.theta0_deg = theta0;
    band.model = "reconstruction";
    band.ratio[0] = band.ratio[1] = band.ratio[2] = NAN;
    const std::string line = band.BriefReport();
    EXPECT_EQ(line.find("nan"), std::string::npos) << line;
    EXPECT_NE(line.find("no samples"), std::string::npos) << line;
  }
  BandAgreement band;
  band.theta0_deg = 30;
  band.samples = 812;
  band.ratio[0] = 1.002, band.ratio[1] = 0.998, band.ratio[2] = 1.01;
  EXPECT_EQ(band.BriefReport(),
            "incidence plane 30 deg: median sample / reconstruction R G B 1.002 0.998 1.010 over 812 samples");
}

}  // namespace
}  // namespace ibrdf
