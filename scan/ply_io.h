// Strict PLY reading and writing (Turk's format: ASCII, binary little- and big-endian).
//
// Reads the vertex element (x, y, z; optional nx, ny, nz; the scan stage's quality, fit_neighbours and
// hull_distance, which WritePly writes; colours and other properties are read and ignored), faces (vertex_indices or
// vertex_index lists; polygons are fanned into triangles), and the Cyberware `range_grid` element of raw range images
// (one list of 0 or 1 vertex index per cell, row-major, its size given by `obj_info num_cols` and `obj_info num_rows`).
// Any other element is read and skipped. COLMAP's fused.ply (with normals) and meshed-*.ply are plain variants.
//
// Why not PCL's or OpenMesh's reader: both report a bad file only as a failed return value with a
// console line, and neither notices a header whose counts lie. Here every defect is an Error naming the
// file and what is wrong: a missing or unknown header line, an unsupported type, a body that ends
// early ("ends after 12 of 40256 vertices"), a line with the wrong number of values, data after the
// last element (the header's counts are wrong), an index out of range, a NaN coordinate.
#pragma once

#include <string>
#include <vector>

#include "core/kind.h"
#include "scan/scan_mesh.h"

namespace ibrdf {

// Reads a PLY file into points, triangles, normals (when the file has nx, ny, nz) and a range grid
// (when it has a range_grid element). Throws Error naming the file on any defect.
ScanMesh ReadPly(const std::string& path);

// Writes the mesh as binary little-endian PLY, atomically (temporary file, then rename). Vertex
// properties: double x, y, z; then, where the mesh has them, float nx, ny, nz; float quality (the
// local-plane fit's RMS residual, metres); int fit_neighbours; float hull_distance (metres). Faces:
// list uchar int vertex_indices. See docs/scan.md.
void WritePly(const std::string& path, const ScanMesh& mesh);

// The type of an extra vertex property (a closed set: the switch in ply_io.cc lists each).
enum class PlyPropertyType {
  kUchar,  // 0-255 (colours: red, green, blue)
  kInt,
  kFloat,
  IBRDF_DUMMY_KIND
};

// A vertex property beyond the mesh's own, one value per vertex (written as its type: rounded and
// clamped for uchar, rounded for int).
struct PlyVertexProperty {
  std::string name;
  PlyPropertyType type = PlyPropertyType::kFloat;
  std::vector<double> values;
};

// The same, with `extra` properties after the mesh's own (each of mesh.points.size() values, else an
// InternalError) and `comment` as the header's comment line.
void WritePly(const std::string& path, const ScanMesh& mesh, const std::vector<PlyVertexProperty>& extra,
              const std::string& comment);

}  // namespace ibrdf
