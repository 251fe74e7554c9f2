// The strict PLY reader: ASCII and binary, range grids, COLMAP-style normals and colours, and every
// kind of bad file answered with an Error that names the file and what is wrong.
#include "scan/ply_io.h"

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>

#include <gtest/gtest.h>

#include "core/error.h"
#include "tests/scan/scan_test_util.h"
#include "tests/scratch_dir.h"

namespace ibrdf {
namespace {

using testing::ScratchDir;
using testing::WriteText;

const char kTriangleAscii[] =
    "ply\nformat ascii 1.0\ncomment a triangle\nelement vertex 3\nproperty float x\nproperty float y\n"
    "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"
    "0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";

// Expects ReadPly to throw an Error whose message names the file and contains `what`.
void ExpectPlyError(const std::string& path, const std::string& what) {
  try {
    ReadPly(path);
    ADD_FAILURE() << "no error for " << path;
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find(what), std::string::npos) << e.what();
  }
}

TEST(PlyIo, ReadsAsciiTriangle) {
  ScratchDir dir;
  WriteText(dir / "t.ply", kTriangleAscii);
  const ScanMesh mesh = ReadPly(dir / "t.ply");
  ASSERT_EQ(mesh.points.size(), 3u);
  ASSERT_EQ(mesh.faces.size(), 1u);
  EXPECT_EQ(mesh.faces[0], Eigen::Vector3i(0, 1, 2));
  EXPECT_TRUE(mesh.normals.empty());
  EXPECT_TRUE(mesh.grid.Empty());
}

TEST(PlyIo, FansPolygonsAndSkipsUnknownElements) {
  ScratchDir dir;
  WriteText(dir / "q.ply",
            "ply\nformat ascii 1.0\nelement vertex 4\nproperty double x\nproperty double y\nproperty double z\n"
            "property uchar red\nproperty uchar green\nproperty uchar blue\n"
            "element face 1\nproperty list uchar int vertex_indices\nelement material 1\nproperty float shine\n"
            "end_header\n0 0 0 255 0 0\n1 0 0 0 255 0\n1 1 0 0 0 255\n0 1 0 9 9 9\n4 0 1 2 3\n0.5\n");
  const ScanMesh mesh = ReadPly(dir / "q.ply");
  EXPECT_EQ(mesh.points.size(), 4u);
  ASSERT_EQ(mesh.faces.size(), 2u);
  EXPECT_EQ(mesh.faces[1], Eigen::Vector3i(0, 2, 3));
}

// COLMAP's fused.ply: binary, float x y z nx ny nz, uchar red green blue.
TEST(PlyIo, ReadsColmapFusedCloudWithNormals) {
  ScratchDir dir;
  std::string data =
      "ply\nformat binary_little_endian 1.0\nelement vertex 2\nproperty float x\nproperty float y\nproperty float z\n"
      "property float nx\nproperty float ny\nproperty float nz\nproperty uchar red\nproperty uchar green\n"
      "property uchar blue\nend_header\n";
  for (int i = 0; i < 2; ++i) {
    const float values[6] = {1.0f * i, 2.0f, 3.0f, 0.0f, 0.0f, 1.0f};
    data.append(reinterpret_cast<const char*>(values), sizeof(values));
    const unsigned char rgb[3] = {10, 20, 30};
    data.append(reinterpret_cast<const char*>(rgb), 3);
  }
  WriteText(dir / "fused.ply", data);
  const ScanMesh mesh = ReadPly(dir / "fused.ply");
  ASSERT_EQ(mesh.points.size(), 2u);
  EXPECT_EQ(mesh.points[1], Eigen::Vector3d(1, 2, 3));
  ASSERT_EQ(mesh.normals.size(), 2u);
  EXPECT_EQ(mesh.normals[0], Eigen::Vector3d(0, 0, 1));
  EXPECT_TRUE(mesh.faces.empty());
}

TEST(PlyIo, ReadsBigEndian) {
  ScratchDir dir;
  std::string data =
      "ply\nformat binary_big_endian 1.0\nelement vertex 1\nproperty double x\nproperty double y\nproperty double z\n"
      "end_header\n";
  for (double v : {1.5, -2.0, 1e4}) {
    unsigned char bytes[8];
    std::memcpy(bytes, &v, 8);
    std::reverse(bytes, bytes + 8);
    data.append(reinterpret_cast<const char*>(bytes), 8);
  }
  WriteText(dir / "b.ply", data);
  EXPECT_EQ(ReadPly(dir / "b.ply").points[0], Eigen::Vector3d(1.5, -2.0, 1e4));
}

TEST(PlyIo, ReadsRangeGrid) {
  ScratchDir dir;
  WriteText(dir / "g.ply",
            "ply\nformat ascii 1.0\nobj_info num_cols 3\nobj_info num_rows 2\nelement vertex 4\nproperty float x\n"
            "property float y\nproperty float z\nelement range_grid 6\nproperty list uchar int vertex_indices\n"
            "end_header\n0 0 0\n1 0 0\n0 1 0\n1 1 0\n1 0\n1 1\n0\n1 2\n1 3\n0\n");
  const ScanMesh mesh = ReadPly(dir / "g.ply");
  ASSERT_FALSE(mesh.grid.Empty());
  EXPECT_EQ(mesh.grid.rows, 2);
  EXPECT_EQ(mesh.grid.cols, 3);
  EXPECT_EQ(mesh.grid.At(0, 0), 0);
  EXPECT_EQ(mesh.grid.At(0, 2), -1);
  EXPECT_EQ(mesh.grid.At(1, 1), 3);
}

TEST(PlyIo, WriteThenReadKeepsEverything) {
  ScratchDir dir;
  ScanMesh mesh;
  mesh.points = {{1e4 + 1e-9, 0, 0}, {1e4, 1e-3, 0}, {1e4, 0, 1e-3}};
  mesh.faces = {{0, 1, 2}};
  mesh.normals = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  mesh.fit_rms_m = {1e-4f, 2e-4f, 3e-4f};
  mesh.fit_neighbours = {10, 11, 12};
  mesh.hull_distance_m = {0.0f, 1e-3f, 2e-3f};
  WritePly(dir / "out.ply", mesh);
  const ScanMesh back = ReadPly(dir / "out.ply");
  ASSERT_EQ(back.points.size(), 3u);
  EXPECT_EQ(back.points[0], mesh.points[0]);  // doubles: exact, also 10 km out
  EXPECT_EQ(back.faces[0], mesh.faces[0]);
  ASSERT_EQ(back.normals.size(), 3u);
  EXPECT_EQ(back.normals[2], mesh.normals[2]);
}

TEST(PlyIo, ExtraVertexPropertiesAreWrittenAndSkippedOnReading) {
  ScratchDir dir;
  ScanMesh mesh;
  mesh.points = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  mesh.faces = {{0, 1, 2}};
  WritePly(dir / "extra.ply", mesh,
           {{"label", PlyPropertyType::kInt, {-1, 2, 3}},
            {"weight", PlyPropertyType::kFloat, {0.25, 0.5, 1.0}},
            {"red", PlyPropertyType::kUchar, {-4, 127.6, 300}}},
           "a test");
  const ScanMesh back = ReadPly(dir / "extra.ply");
  ASSERT_EQ(back.points.size(), 3u);
  EXPECT_EQ(back.points[1], mesh.points[1]);
  EXPECT_EQ(back.faces[0], mesh.faces[0]);
  std::ifstream in(dir / "extra.ply", std::ios::binary);
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const size_t body = text.find("end_header\n");
  ASSERT_NE(body, std::string::npos);
  EXPECT_NE(text.find("comment a test\n"), std::string::npos);
  EXPECT_NE(text.find("property int label\nproperty float weight\nproperty uchar red\n"), std::string::npos);
  // Vertex 1: x y z (doubles), label, weight, red.
  const char* v1 = text.data() + body + 11 + (24 + 4 + 4 + 1);
  int32_t label = 0;
  float weight = 0;
  std::memcpy(&label, v1 + 24, 4);
  std::memcpy(&weight, v1 + 28, 4);
  EXPECT_EQ(label, 2);
  EXPECT_EQ(weight, 0.5f);
  EXPECT_EQ(uint8_t(v1[32]), 128);                                  // rounded
  EXPECT_EQ(uint8_t(text[body + 11 + 32]), 0);                      // clamped below
  EXPECT_EQ(uint8_t(text[body + 11 + 2 * 33 + 32]), 255);           // and above
  EXPECT_THROW(WritePly(dir / "bad.ply", mesh, {{"label", PlyPropertyType::kInt, {1, 2}}}, "x"), InternalError);
  EXPECT_FALSE(std::filesystem::exists(dir / "bad.ply"));
}

TEST(PlyIo, ReadsTheBunnyRangeGrid) {
  IBRDF_REQUIRE_BUNNY();
  const ScanMesh mesh = ReadPly(testing::BunnyDir() + "/bun000.ply");
  EXPECT_EQ(mesh.points.size(), 40256u);
  EXPECT_EQ(mesh.grid.cols, 512);
  EXPECT_EQ(mesh.grid.rows, 400);
  size_t filled = 0;
  for (int v : mesh.grid.cell_point) filled += v >= 0;
  EXPECT_EQ(filled, 40256u);
}

TEST(PlyIo, EmptyFileIsAnError) {
  ScratchDir dir;
  WriteText(dir / "empty.ply", "");
  ExpectPlyError(dir / "empty.ply", "empty file");
}

TEST(PlyIo, MissingFileIsAnError) {
  ScratchDir dir;
  ExpectPlyError(dir / "nothing.ply", "does not exist");
}

TEST(PlyIo, TruncatedAsciiIsAnError) {
  ScratchDir dir;
  const std::string text = kTriangleAscii;
  WriteText(dir / "cut.ply", text.substr(0, text.find("0 1 0\n")));
  // Caught before reading: the header's counts need more bytes than the file holds.
  ExpectPlyError(dir / "cut.ply", "3 vertex entries need at least 6 bytes each, but only 13 bytes follow");
  // Cut inside the face list, the body is read and ends early.
  WriteText(dir / "cut2.ply", text.substr(0, text.size() - 2) + "  \n");
  ExpectPlyError(dir / "cut2.ply", "the file ends inside face 0");
}

TEST(PlyIo, TruncatedHeaderIsAnError) {
  ScratchDir dir;
  WriteText(dir / "cut.ply", "ply\nformat ascii 1.0\nelement vertex 3\n");
  ExpectPlyError(dir / "cut.ply", "no end_header");
}

TEST(PlyIo, TruncatedBinaryIsAnError) {
  ScratchDir dir;
  ScanMesh mesh;
  mesh.points = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  mesh.faces = {{0, 1, 2}};
  WritePly(dir / "full.ply", mesh);
  std::ifstream in(dir / "full.ply", std::ios::binary);
  std::string data((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  WriteText(dir / "cut.ply", data.substr(0, data.size() - 5));
  ExpectPlyError(dir / "cut.ply", "truncated");
}

TEST(PlyIo, HeaderClaimingTooFewVerticesIsAnError) {
  ScratchDir dir;
  std::string text = kTriangleAscii;
  text.replace(text.find("element vertex 3"), 16, "element vertex 2");
  WriteText(dir / "lie.ply", text);
  ExpectPlyError(dir / "lie.ply", "");  // the third vertex is read as a face: a clear error either way
  WriteText(dir / "lie2.ply", std::string(kTriangleAscii) + "3 0 1 2\n");  // one face more than declared
  ExpectPlyError(dir / "lie2.ply", "header's counts are wrong");
}

TEST(PlyIo, HeaderClaimingTooManyVerticesIsAnError) {
  ScratchDir dir;
  std::string text = kTriangleAscii;
  text.replace(text.find("element vertex 3"), 16, "element vertex 4");
  WriteText(dir / "lie.ply", text);
  ExpectPlyError(dir / "lie.ply", "vertex 3");
}

TEST(PlyIo, BinaryWithExtraBytesIsAnError) {
  ScratchDir dir;
  ScanMesh mesh;
  mesh.points = {{0, 0, 0}};
  WritePly(dir / "one.ply", mesh);
  std::ifstream in(dir / "one.ply", std::ios::binary);
  std::string data((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  WriteText(dir / "more.ply", data + std::string(24, '\0'));
  ExpectPlyError(dir / "more.ply", "header's counts are wrong");
}

TEST(PlyIo, NanCoordinateIsAnError) {
  ScratchDir dir;
  std::string text = kTriangleAscii;
  text.replace(text.find("1 0 0\n"), 6, "1 nan 0\n");
  WriteText(dir / "nan.ply", text);
  ExpectPlyError(dir / "nan.ply", "vertex 1 has a NaN");
}

TEST(PlyIo, FaceIndexOutOfRangeIsAnError) {
  ScratchDir dir;
  std::string text = kTriangleAscii;
  text.replace(text.find("3 0 1 2"), 7, "3 0 1 7");
  WriteText(dir / "index.ply", text);
  ExpectPlyError(dir / "index.ply", "refers to vertex 7");
}

TEST(PlyIo, MalformedHeadersAreErrors) {
  ScratchDir dir;
  WriteText(dir / "a.ply", "not a ply\n");
  ExpectPlyError(dir / "a.ply", "not a PLY file");
  WriteText(dir / "b.ply", "ply\nformat ascii 1.0\nelement vertex 1\nproperty quad x\nend_header\n0\n");
  ExpectPlyError(dir / "b.ply", "unknown type 'quad'");
  WriteText(dir / "c.ply",
            "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nend_header\n0 0\n");
  ExpectPlyError(dir / "c.ply", "needs properties x, y and z");
  WriteText(dir / "d.ply", "ply\nformat ascii 1.0\nfrobnicate\nend_header\n");
  ExpectPlyError(dir / "d.ply", "unknown header line");
  WriteText(dir / "e.ply",
            "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nproperty float z\n"
            "element range_grid 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0\n");
  ExpectPlyError(dir / "e.ply", "num_cols");
  WriteText(dir / "f.ply",
            std::string(kTriangleAscii).replace(std::string(kTriangleAscii).find("1 0 0\n"), 6, "1 x 0\n"));
  ExpectPlyError(dir / "f.ply", "'x' is not a number");
}

// A 300-byte file declaring a 100000 x 20000 range grid must not allocate 8 GB before reading data.
TEST(PlyIo, CountsAreCheckedAgainstTheFileSizeBeforeAllocating) {
  ScratchDir dir;
  WriteText(dir / "huge.ply",
            "ply\nformat ascii 1.0\nobj_info num_cols 100000\nobj_info num_rows 20000\nelement vertex 1\n"
            "property float x\nproperty float y\nproperty float z\nelement range_grid 2000000000\n"
            "property list uchar int vertex_indices\nend_header\n0 0 0\n1 0\n");
  ExpectPlyError(dir / "huge.ply", "range_grid entries need at least");
  std::string binary =
      "ply\nformat binary_little_endian 1.0\nelement vertex 4000000000\nproperty float x\nproperty float y\n"
      "property float z\nend_header\n";
  binary.append(12, '\0');
  WriteText(dir / "huge_binary.ply", binary);
  ExpectPlyError(dir / "huge_binary.ply", "vertex entries need at least 12 bytes");
}

// Negative range-grid indices and NaN quality must not be accepted silently.
TEST(PlyIo, NegativeIndicesAndNonFiniteValuesAreErrors) {
  ScratchDir dir;
  WriteText(dir / "g.ply",
            "ply\nformat ascii 1.0\nobj_info num_cols 2\nobj_info num_rows 1\nelement vertex 1\nproperty float x\n"
            "property float y\nproperty float z\nelement range_grid 2\nproperty list uchar int vertex_indices\n"
            "end_header\n0 0 0\n1 -5\n0\n");
  ExpectPlyError(dir / "g.ply", "vertex index -5");
  WriteText(dir / "q.ply",
            "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
            "property float quality\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"
            "0 0 0 nan\n1 0 0 1\n0 1 0 1\n3 0 1 2\n");
  ExpectPlyError(dir / "q.ply", "vertex 0: quality");
  WriteText(dir / "big.ply",
            "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
            "element face 1\nproperty list uchar uint vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n"
            "3 0 1 4000000000\n");
  ExpectPlyError(dir / "big.ply", "negative or too large");
}

// A binary range grid of 2 x 3 cells, each holding its vertex, with `declared` vertices in the header.
std::string BinaryRangeGrid(int declared) {
  std::string ply = "ply\nformat binary_little_endian 1.0\nobj_info num_cols 3\nobj_info num_rows 2\nelement vertex " +
                    std::to_string(declared) +
                    "\nproperty float x\nproperty float y\nproperty float z\nelement range_grid 6\n"
                    "property list uchar int vertex_indices\nend_header\n";
  for (int v = 0; v < 6; ++v) {
    const float p[3] = {0.001f * (v % 3), 0.001f * (v / 3), 0.5f};
    ply.append(reinterpret_cast<const char*>(p), sizeof(p));
  }
  for (int32_t v = 0; v < 6; ++v) {
    ply.push_back('\1');
    ply.append(reinterpret_cast<const char*>(&v), sizeof(v));
  }
  return ply;
}

// A vertex count one too high in a binary range grid: the extra vertex takes the first cells' bytes and
// the cells after it re-synchronize, so the byte count comes out even and the grid loses three cells.
// The data no longer matches the header, which must be an error naming the elements and counts.
TEST(PlyIo, BinaryRangeGridWithWrongVertexCountIsAnError) {
  ScratchDir dir;
  WriteText(dir / "ok.ply", BinaryRangeGrid(6));
  const ScanMesh mesh = ReadPly(dir / "ok.ply");
  EXPECT_EQ(mesh.points.size(), 6u);
  EXPECT_EQ(mesh.grid.At(1, 2), 5);
  WriteText(dir / "plus1.ply", BinaryRangeGrid(7));
  ExpectPlyError(dir / "plus1.ply", "3 of the 6 range_grid cells hold a vertex");
  ExpectPlyError(dir / "plus1.ply", "the header declares vertex 7, range_grid 6");
  WriteText(dir / "minus1.ply", BinaryRangeGrid(5));
  ExpectPlyError(dir / "minus1.ply", "the header declares vertex 5, range_grid 6");
}

// A coordinate no scan of a sample has (3e38 m, finite as a float) is an error naming the vertex.
TEST(PlyIo, AbsurdCoordinateIsAnError) {
  ScratchDir dir;
  std::string text = kTriangleAscii;
  text.replace(text.find("1 0 0\n"), 6, "3e38 0 0\n");
  WriteText(dir / "far.ply", text);
  ExpectPlyError(dir / "far.ply", "vertex 1 lies at");
}

// Bytes left after the last element: the error names the elements and the counts the header declares.
TEST(PlyIo, BinaryTrailingBytesNameTheElementsAndCounts) {
  ScratchDir dir;
  std::string ply =
      "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
      "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n";
  const float p[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  ply.append(reinterpret_cast<const char*>(p), sizeof(p));
  const int32_t face[3] = {0, 1, 2};
  ply.push_back('\3');
  ply.append(reinterpret_cast<const char*>(face), sizeof(face));
  WriteText(dir / "exact.ply", ply);
  EXPECT_EQ(ReadPly(dir / "exact.ply").faces.size(), 1u);
  WriteText(dir / "long.ply", ply + std::string(12, '\0'));
  ExpectPlyError(dir / "long.ply", "12 bytes after");
  ExpectPlyError(dir / "long.ply", "the header declares vertex 3, face 1");
}

}  // namespace
}  // namespace ibrdf
