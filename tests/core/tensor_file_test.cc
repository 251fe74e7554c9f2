#include "core/tensor_file.h"

#include <cstring>
#include <fstream>

#include <gtest/gtest.h>

#include "core/piecewise_linear_2d.h"
#include "tests/error_of.h"
#include "tests/scratch_dir.h"

namespace ibrdf {
namespace {

using testing::ErrorOf;
using testing::ScratchDir;

TEST(TensorFile, RoundTripsFieldsBitExactly) {
  ScratchDir dir;
  TensorFile file;
  file["description"] = TextField("ibrdf test");
  file["values"] = FloatField({2, 3}, {1.0f, 2.5f, -3.0f, 1e-20f, 7.0f, 0.0f});
  file["flag"] = BytesField({1});
  WriteTensorFile(dir / "t.bsdf", file);
  const TensorFile read = ReadTensorFile(dir / "t.bsdf");
  ASSERT_EQ(read.size(), 3u);
  for (const auto& [name, field] : file) {
    ASSERT_TRUE(read.count(name)) << name;
    EXPECT_EQ(read.at(name).dtype, field.dtype) << name;
    EXPECT_EQ(read.at(name).shape, field.shape) << name;
    EXPECT_EQ(read.at(name).data, field.data) << name;
  }
  EXPECT_EQ(read.at("values").Describe(), "float32 [2, 3]");
}

TEST(TensorFile, HeaderBytesAreTheFormats) {
  // The layout Mitsuba's tensor_io and brdf-loader read: magic, version 1.0, uint32 count, then the
  // field record (uint16 name length, name, uint16 rank, uint8 dtype, uint64 offset, uint64 shape).
  ScratchDir dir;
  TensorFile file;
  file["x"] = FloatField({2}, {1.0f, 2.0f});
  WriteTensorFile(dir / "t.bsdf", file);
  std::ifstream in(dir / "t.bsdf", std::ios::binary);
  std::vector<char> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  ASSERT_GE(bytes.size(), 18u + 2 + 1 + 2 + 1 + 8 + 8 + 8);
  EXPECT_EQ(std::memcmp(bytes.data(), "tensor_file\0", 12), 0);
  EXPECT_EQ(bytes[12], 1);
  EXPECT_EQ(bytes[13], 0);
  uint32_t count;
  std::memcpy(&count, bytes.data() + 14, 4);
  EXPECT_EQ(count, 1u);
  uint16_t name_length, rank;
  std::memcpy(&name_length, bytes.data() + 18, 2);
  EXPECT_EQ(name_length, 1);
  EXPECT_EQ(bytes[20], 'x');
  std::memcpy(&rank, bytes.data() + 21, 2);
  EXPECT_EQ(rank, 1);
  EXPECT_EQ(bytes[23], 10);  // float32
  uint64_t offset, shape;
  std::memcpy(&offset, bytes.data() + 24, 8);
  std::memcpy(&shape, bytes.data() + 32, 8);
  EXPECT_EQ(shape, 2u);
  EXPECT_EQ(offset % 8, 0u);
  float first;
  std::memcpy(&first, bytes.data() + offset, 4);
  EXPECT_EQ(first, 1.0f);
}

TEST(TensorFile, BadFilesNameTheFileAndTheProblem) {
  ScratchDir dir;
  {
    std::ofstream out(dir / "bad.bsdf", std::ios::binary);
    out << "not a tensor file at all";
  }
  EXPECT_NE(ErrorOf([&] { ReadTensorFile(dir / "bad.bsdf"); }).find("bad.bsdf: not a tensor file"), std::string::npos);
  TensorFile file;
  file["x"] = FloatField({4}, {1, 2, 3, 4});
  WriteTensorFile(dir / "t.bsdf", file);
  std::filesystem::resize_file(dir / "t.bsdf", std::filesystem::file_size(dir / "t.bsdf") - 8);
  EXPECT_NE(ErrorOf([&] { ReadTensorFile(dir / "t.bsdf"); }).find("runs past the end of the file"), std::string::npos);
  EXPECT_NE(ErrorOf([&] { ReadTensorFile(dir / "missing.bsdf"); }).find("missing.bsdf"), std::string::npos);
  const TensorFile good = [&] {
    WriteTensorFile(dir / "g.bsdf", file);
    return ReadTensorFile(dir / "g.bsdf");
  }();
  EXPECT_NE(
      ErrorOf([&] { RequireField(good, "g.bsdf", "ndf", TensorType::kFloat32, 2); }).find("missing field \"ndf\""),
      std::string::npos);
  EXPECT_NE(ErrorOf([&] { RequireField(good, "g.bsdf", "x", TensorType::kFloat32, 2); }).find("float32 [4]"),
            std::string::npos);
}

// The warp: Invert undoes Sample, densities integrate to 1, Eval interpolates bilinearly.
TEST(PiecewiseLinear2D, SampleAndInvertAreInversesAndTheDensityIsNormalized) {
  const uint32_t nx = 5, ny = 4;
  std::vector<float> data(2 * nx * ny);
  for (uint32_t i = 0; i < data.size(); ++i) data[i] = 0.2f + float((i * 7) % 11);
  const PiecewiseLinear2D warp(nx, ny, data.data(), {{0.0f, 1.0f}});
  for (float param : {0.0f, 0.3f, 1.0f}) {
    double integral = 0.0;
    const int n = 200;
    for (int y = 0; y < n; ++y) {
      for (int x = 0; x < n; ++x) integral += warp.Eval({(x + 0.5f) / n, (y + 0.5f) / n}, &param) / (n * n);
    }
    EXPECT_NEAR(integral, 1.0, 2e-3) << param;
    for (float sx : {0.1f, 0.37f, 0.5f, 0.93f}) {
      for (float sy : {0.05f, 0.42f, 0.77f}) {
        const auto [p, pdf] = warp.Sample({sx, sy}, &param);
        const auto [s, pdf2] = warp.Invert(p, &param);
        EXPECT_NEAR(s.x(), sx, 2e-4) << param;
        EXPECT_NEAR(s.y(), sy, 2e-4) << param;
        EXPECT_NEAR(pdf, pdf2, 1e-3 * pdf);
        EXPECT_NEAR(pdf, warp.Eval(p, &param), 1e-3 * pdf);
      }
    }
  }
  // Raw values (no normalization): bilinear between the nodes.
  const float raw[4] = {1.0f, 3.0f, 5.0f, 7.0f};
  const PiecewiseLinear2D plain(2, 2, raw, {}, false, false);
  EXPECT_NEAR(plain.Eval({0.5f, 0.5f}), 4.0f, 1e-6);
  EXPECT_NEAR(plain.Eval({1.0f, 0.0f}), 3.0f, 1e-6);
  EXPECT_NEAR(plain.Eval({0.25f, 1.0f}), 5.5f, 1e-6);
}

}  // namespace
}  // namespace ibrdf
