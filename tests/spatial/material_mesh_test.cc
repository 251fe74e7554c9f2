// The mesh with each vertex's material: a vertex takes its own cell's weights, else the nearest fitted
// cell's within 1.5 cell edges, else none, in the world frame of the session's world_from_mesh; an
// analytic sample writes nothing and says why; OpenMesh's PLY reader reads the file with its colours.
#include "spatial/material_mesh.h"

// OpenMesh's property containers trip GCC 12's -Wmaybe-uninitialized (as in scan/openmesh_adapters.cc).
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>

#include <OpenMesh/Core/IO/MeshIO.hh>
#include <OpenMesh/Core/Mesh/TriMesh_ArrayKernelT.hh>
#include <gtest/gtest.h>

#include "scan/ply_io.h"
#include "spatial/uniformity.h"
#include "tests/scratch_dir.h"

namespace ibrdf {
namespace {

using testing::ScratchDir;

struct Vertex {
  Eigen::Vector3d p;
  int32_t label;
  float w0, w3, residual;
  uint8_t fits, from;
  float sum;
  uint8_t rgb[3];
};

// The vertices of materials.ply with two bases (groups 0 and 3): 49 bytes each.
std::vector<Vertex> ReadVertices(const std::string& path, size_t n) {
  std::ifstream in(path, std::ios::binary);
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const char* at = text.data() + text.find("end_header\n") + 11;
  std::vector<Vertex> out(n);
  for (Vertex& v : out) {
    std::memcpy(v.p.data(), at, 24);
    std::memcpy(&v.label, at + 24, 4);
    std::memcpy(&v.w0, at + 28, 4);
    std::memcpy(&v.w3, at + 32, 4);
    std::memcpy(&v.residual, at + 36, 4);
    v.fits = uint8_t(at[40]);
    v.from = uint8_t(at[41]);
    std::memcpy(&v.sum, at + 42, 4);
    for (int k = 0; k < 3; ++k) v.rgb[k] = uint8_t(at[46 + k]);
    at += 49;
  }
  return out;
}

CellWeights Cell(const Eigen::Vector3d& centre, double cell_m, Eigen::VectorXd weights, bool fits) {
  CellWeights cell;
  cell.key = UniformityCellKey(centre, Eigen::Vector3d::Zero(), cell_m);
  cell.centre = centre;
  cell.samples = 100;
  cell.fitted = weights.size() > 0;
  cell.weights = weights;
  cell.rel_rms = 0.04;
  cell.fits = fits;
  if (cell.fitted) cell.weights.maxCoeff(&cell.dominant);
  return cell;
}

TEST(MaterialMesh, VerticesTakeTheirCellsWeightsInTheWorldFrame) {
  ScratchDir dir;
  const double cell_m = 0.01;
  // Mesh frame; the world is 1 cm along x.
  ScanMesh mesh;
  mesh.points = {{0.001, 0.001, 0.001}, {0.005, 0.005, 0.005}, {0.015, 0.005, 0.005}, {0.09, 0.0, 0.0},
                 {0.045, 0.045, 0.045}};
  mesh.faces = {{0, 1, 2}, {2, 3, 4}};
  WritePly(dir / "mesh.ply", mesh);
  Session session;
  session.directory = dir.str();
  session.sample.kind = SampleSpec::Kind::kMesh;
  session.sample.mesh_file = "mesh.ply";
  session.sample.world_from_mesh.translation = Eigen::Vector3d(0.01, 0.0, 0.0);

  MaterialWeightsResult weights;
  weights.bases = 2;
  Eigen::VectorXd mix(2), other(2);
  mix << 0.2, 0.6;
  other << 1.0, 0.0;
  weights.cells = {Cell({0.013, 0.003, 0.003}, cell_m, mix, true),            // vertices 0, 1
                   Cell({0.025, 0.005, 0.005}, cell_m, Eigen::VectorXd(), false),  // vertex 2's: not fitted
                   Cell({0.055, 0.045, 0.045}, cell_m, other, false)};          // vertex 4's: fits none
  const MaterialMeshResult result =
      WriteMaterialMesh(session, weights, {0, 3}, Eigen::Vector3d::Zero(), cell_m, dir / "materials.ply");
  ASSERT_TRUE(result.written) << result.not_written;
  EXPECT_EQ(result.vertices, 5u);
  EXPECT_EQ(result.own_cell, 3u);
  EXPECT_EQ(result.near_cell, 1u);
  EXPECT_EQ(result.none, 1u);
  EXPECT_EQ(result.not_fitting, 1u);
  EXPECT_NE(result.BriefReport().find("5 vertices"), std::string::npos) << result.BriefReport();

  const ScanMesh back = ReadPly(dir / "materials.ply");
  ASSERT_EQ(back.faces.size(), 2u);
  const std::vector<Vertex> v = ReadVertices(dir / "materials.ply", 5);
  EXPECT_NEAR(v[0].p.x(), 0.011, 1e-12);  // world frame
  for (int i : {0, 1, 2}) {
    EXPECT_EQ(v[size_t(i)].label, 3) << i;  // the larger weight's group
    EXPECT_FLOAT_EQ(v[size_t(i)].w0, 0.25f) << i;
    EXPECT_FLOAT_EQ(v[size_t(i)].w3, 0.75f) << i;
    EXPECT_FLOAT_EQ(v[size_t(i)].residual, 0.04f) << i;
    EXPECT_EQ(v[size_t(i)].fits, 1) << i;
    EXPECT_FLOAT_EQ(v[size_t(i)].sum, 0.8f) << i;  // the weights before normalising: the cell's brightness
  }
  EXPECT_EQ(v[0].from, uint8_t(VertexWeightsFrom::kOwnCell));
  EXPECT_EQ(v[2].from, uint8_t(VertexWeightsFrom::kNearCell));
  EXPECT_EQ(v[3].from, uint8_t(VertexWeightsFrom::kNone));
  EXPECT_EQ(v[3].label, -1);
  EXPECT_EQ(v[3].w0 + v[3].w3, 0.0f);
  EXPECT_EQ(v[3].sum, 0.0f);
  EXPECT_EQ(v[3].rgb[0], 128);  // grey: no weights
  EXPECT_EQ(v[4].fits, 0);
  EXPECT_EQ(v[4].label, 0);
  EXPECT_EQ(v[4].rgb[0], 255);  // magenta: fits no combination
  EXPECT_EQ(v[4].rgb[1], 0);

  // A reader nobody here wrote (OpenMesh's PLY reader) takes the file with its colours.
  OpenMesh::TriMesh_ArrayKernelT<> om;
  om.request_vertex_colors();
  OpenMesh::IO::Options options = OpenMesh::IO::Options::VertexColor;
  ASSERT_TRUE(OpenMesh::IO::read_mesh(om, dir / "materials.ply", options));
  EXPECT_EQ(om.n_vertices(), 5u);
  EXPECT_EQ(om.n_faces(), 2u);
  ASSERT_TRUE(options.check(OpenMesh::IO::Options::VertexColor));
  const auto magenta = om.color(OpenMesh::VertexHandle(4)), grey = om.color(OpenMesh::VertexHandle(3));
  EXPECT_EQ(int(magenta[0]), 255);
  EXPECT_EQ(int(magenta[1]), 0);
  EXPECT_EQ(int(magenta[2]), 255);
  EXPECT_EQ(int(grey[1]), 128);
  EXPECT_NEAR(om.point(OpenMesh::VertexHandle(0))[0], 0.011, 1e-6);

  session.sample.kind = SampleSpec::Kind::kSphere;
  const MaterialMeshResult sphere =
      WriteMaterialMesh(session, weights, {0, 3}, Eigen::Vector3d::Zero(), cell_m, dir / "sphere.ply");
  EXPECT_FALSE(sphere.written);
  EXPECT_NE(sphere.not_written.find("analytic"), std::string::npos);
  EXPECT_FALSE(std::filesystem::exists(dir / "sphere.ply"));
}

}  // namespace
}  // namespace ibrdf
