#include "spatial/material_scene.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <unordered_map>

#include "core/error.h"
#include "core/file_util.h"
#include "core/image_io.h"
#include "core/kind.h"
#include "core/logging.h"
#include "core/statistics.h"
#include "scan/ply_io.h"
#include "spatial/uniformity.h"

namespace ibrdf {
namespace {

// A face's material: basis `a` alone (amount 0), or pbrt's mix of a and b picking b with `amount`.
struct FaceMaterial {
  int a = -1, b = -1;
  int steps = 0;  // amount = steps * amount_step
  int level = 0;  // its brightness, level * scale_step of the light's scale (the full level: no black mixed in)
  bool operator<(const FaceMaterial& o) const {
    return std::tie(a, b, steps, level) < std::tie(o.a, o.b, o.steps, o.level);
  }
};

// The largest weight's index and the second largest positive one's (-1: none).
std::pair<Eigen::Index, Eigen::Index> LargestTwo(const Eigen::VectorXd& w) {
  Eigen::Index first = 0;
  w.maxCoeff(&first);
  Eigen::Index second = -1;
  for (Eigen::Index b = 0; b < w.size(); ++b) {
    if (b != first && w[b] > 0.0 && (second < 0 || w[b] > w[second])) second = b;
  }
  return {first, second};
}

std::string Number(double value) {
  std::ostringstream out;
  out.precision(12);
  out << value;
  return out.str();
}

}  // namespace

bool PbrtSceneOptions::Check(std::string* why) const {
  if (!(amount_step > 0.0 && amount_step <= 0.5)) {
    *why = "the mixes' amount step must be in (0, 0.5]";
    return false;
  }
  if (!(scale_step > 0.0 && scale_step <= 0.2)) {
    *why = "the faces' brightness step must be in (0, 0.2]";
    return false;
  }
  if (!(max_scale_percentile > 0.0 && max_scale_percentile <= 1.0)) {
    *why = "the light's scale percentile must be in (0, 1]";
    return false;
  }
  if (samples_per_pixel < 1) {
    *why = "samples per pixel must be positive";
    return false;
  }
  return true;
}

std::string PbrtSceneResult::BriefReport() const {
  if (!written) return "pbrt-v4 scene not written: " + not_written;
  return file + ": photo " + std::to_string(photo) + ", " + std::to_string(faces) + " faces in " +
         std::to_string(materials) + " materials (" +
         Fixed(faces ? 100.0 * double(faces_unmeasured) / double(faces) : 0.0, 1) +
         " % of faces without weights, black); light scale " + Fixed(light_scale, 3) + " (" +
         std::to_string(faces_scale_clipped) + " faces brighter, held at it); render: cd " +
         std::filesystem::path(file).parent_path().string() + " && pbrt " +
         std::filesystem::path(file).filename().string() +
         (model_image.empty() ? std::string()
                              : "; ibrdf's render of the model: " + model_image + " (" + std::to_string(model_pixels) +
                                    " pixels; the cells' weight sums there, median " + Fixed(weight_sum_median, 2) +
                                    ", 5-95 % " + Fixed(weight_sum_p05, 2) + "-" + Fixed(weight_sum_p95, 2) +
                                    "; the model with every weight is " + Fixed(full_model_ratio, 3) + "x as bright)") +
         (mitsuba_file.empty() ? "; no Mitsuba 3 scene: " + mitsuba_not_written : "; Mitsuba 3: " + mitsuba_file);
}

PbrtSceneResult WritePbrtScene(const Session& session, size_t photo, const VertexMaterials& vertices,
                               const std::vector<std::string>& basis_snippets,
                               const std::vector<std::string>& basis_names, const std::string& out_dir,
                               const PbrtSceneOptions& options) {
  std::string why;
  if (!options.Check(&why)) ThrowError("pbrt scene options", why);
  PbrtSceneResult result;
  result.photo = photo;
  if (photo >= session.photos.size() || !session.photos[photo].camera_from_world) {
    result.not_written = "photo " + std::to_string(photo) + " has no pose";
    return result;
  }
  result.undistorted = session.camera.HasDistortion();
  const size_t n_bases = vertices.bases.size();
  if (basis_snippets.size() != n_bases || basis_names.size() != n_bases || n_bases == 0) {
    throw InternalError("WritePbrtScene: a snippet and a name per basis");
  }
  const ScanMesh& mesh = vertices.mesh;

  // Each face: the mean of its vertices' weights, the two largest renormalised and rounded.
  std::vector<std::pair<FaceMaterial, size_t>> measured_faces;
  std::vector<double> face_scales;
  std::vector<size_t> unmeasured;
  for (size_t f = 0; f < mesh.faces.size(); ++f) {
    const Eigen::Vector3i& face = mesh.faces[f];
    Eigen::VectorXd w = Eigen::VectorXd::Zero(Eigen::Index(n_bases));
    bool measured = true;
    for (int k = 0; k < 3; ++k) {
      measured = measured && vertices.from[size_t(face[k])] != VertexWeightsFrom::kNone;
      w += vertices.weights.row(face[k]).transpose();
    }
    if (!measured || !(w.sum() > 0.0)) {
      unmeasured.push_back(f);
      continue;
    }
    FaceMaterial material;
    const auto [first, second] = LargestTwo(w);
    material.a = int(first);
    if (second >= 0) {
      material.b = int(second);
      material.steps = int(std::lround(w[second] / (w[first] + w[second]) / options.amount_step));
      if (material.steps == 0) material.b = -1;
    }
    measured_faces.emplace_back(material, f);
    double scale = 1.0;  // without sums (no scale given), every face at the light's
    if (!vertices.scale.empty()) {
      scale = 0.0;
      for (int k = 0; k < 3; ++k) scale += vertices.scale[size_t(face[k])] / 3.0;
    }
    face_scales.push_back(scale);
  }
  // The faces' brightness: the light is scaled to the 99th percentile of the faces' weight sums (at least
  // 1), and each face mixes its material with black to the rest; brighter faces are held at the light's.
  result.light_scale = face_scales.empty() ? 1.0 : std::max(1.0, Percentile(face_scales, options.max_scale_percentile));
  const int full_level = int(std::lround(1.0 / options.scale_step));
  std::map<FaceMaterial, std::vector<size_t>> parts;
  for (size_t i = 0; i < measured_faces.size(); ++i) {
    FaceMaterial material = measured_faces[i].first;
    const double t = face_scales[i] / result.light_scale;
    if (t > 1.0 + 0.5 * options.scale_step) ++result.faces_scale_clipped;
    material.level = std::clamp(int(std::lround(std::min(t, 1.0) / options.scale_step)), 1, full_level);
    parts[material].push_back(measured_faces[i].second);
  }
  result.faces = mesh.faces.size();
  result.faces_unmeasured = unmeasured.size();

  const std::filesystem::path folder = std::filesystem::path(out_dir) / "pbrt";
  std::filesystem::create_directories(folder);
  // One PLY per material: its faces and the vertices they use (normals kept).
  const auto write_part = [&](const std::vector<size_t>& faces, const std::string& name) {
    ScanMesh part;
    std::vector<int> index(mesh.points.size(), -1);
    const bool normals = mesh.normals.size() == mesh.points.size();
    for (size_t f : faces) {
      Eigen::Vector3i face;
      for (int k = 0; k < 3; ++k) {
        int& at = index[size_t(mesh.faces[f][k])];
        if (at < 0) {
          at = int(part.points.size());
          part.points.push_back(mesh.points[size_t(mesh.faces[f][k])]);
          if (normals) part.normals.push_back(mesh.normals[size_t(mesh.faces[f][k])]);
        }
        face[k] = at;
      }
      part.faces.push_back(face);
    }
    WritePly((folder / name).string(), part, {}, "ibrdf materials: part of the mesh in one material (world frame, metres)");
  };

  const Camera& camera = session.camera;
  const Rigid3d& camera_from_world = *session.photos[photo].camera_from_world;
  Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
  m.topLeftCorner<3, 3>() = camera_from_world.rotation.toRotationMatrix();
  m.topRightCorner<3, 1>() = camera_from_world.translation;
  const double fx = camera.FocalX(), fy = camera.FocalY(), cx = camera.PrincipalX(), cy = camera.PrincipalY();
  const double w = double(camera.width), h = double(camera.height);

  std::ostringstream scene;
  scene
      << "# pbrt-v4: photo " << photo << " of " << session.manifest_path
      << " rendered from ibrdf's measured spatially varying model\n"
      << "# (each face a mix of the two groups of the largest weights, amounts in steps of "
      << Number(options.amount_step) << "; faces without weights black).\n"
      << "# The light's intensity is its scale, the faces' weight sums' "
      << Number(100.0 * options.max_scale_percentile)
      << "th percentile, and each face mixes\n# its material with black down to its own sum: a pixel over (cos theta_i "
         "/ r^2) of its point is the\n"
      << "# model's BRDF there.\n"
      << (result.undistorted
              ? "# The photo's lens distortion is not rendered (pbrt-v4's perspective camera has none): photo "
                "pixel p is\n# rendered at (fx x + cx, fy y + cy), (x, y) the undistorted image-plane point of p.\n"
              : "")
      << "Film \"rgb\" \"integer xresolution\" [ " << camera.width << " ] \"integer yresolution\" [ " << camera.height
      << " ]\n    \"string filename\" \"photo-" << photo << ".exr\" \"bool savefp16\" false\n"
      << "PixelFilter \"box\" \"float xradius\" [ 0.5 ] \"float yradius\" [ 0.5 ]\n"
      << "Sampler \"zsobol\" \"integer pixelsamples\" [ " << options.samples_per_pixel << " ]\n"
      << "Integrator \"path\" \"integer maxdepth\" [ 1 ]\n"
      << "# The photo's camera_from_world, y flipped: pbrt's camera looks down +z with +y up, the photo's y is down.\n"
      << "Scale 1 -1 1\nConcatTransform [";
  for (int col = 0; col < 4; ++col) {
    for (int row = 0; row < 4; ++row) scene << " " << Number(m(row, col));
  }
  // fov 90: screen coordinates are x / z and y / z; the window puts pixel (cx, cy) on the axis.
  scene << " ]\nCamera \"perspective\" \"float fov\" [ 90 ] \"float screenwindow\" [ " << Number(-cx / fx) << " "
        << Number((w - cx) / fx) << " " << Number((cy - h) / fy) << " " << Number(cy / fy) << " ]\n"
        << "WorldBegin\n";
  const Light& light = session.lights[session.photos[photo].light];
  switch (light.kind) {
    case Light::Kind::kPoint:
      scene << "LightSource \"point\" \"point3 from\" [ " << Number(light.position.x()) << " "
            << Number(light.position.y()) << " " << Number(light.position.z()) << " ] \"float scale\" [ "
            << Number(result.light_scale) << " ]\n";
      break;
    case Light::Kind::kDirectional:
      scene << "LightSource \"distant\" \"point3 from\" [ " << Number(light.direction.x()) << " "
            << Number(light.direction.y()) << " " << Number(light.direction.z()) << " ] \"point3 to\" [ 0 0 0 ]"
            << " \"float scale\" [ " << Number(result.light_scale) << " ]\n";
      break;
  }
  for (size_t b = 0; b < n_bases; ++b) scene << "Include \"../" << basis_snippets[b] << "\"\n";
  scene << "MakeNamedMaterial \"unmeasured\" \"string type\" \"diffuse\" \"rgb reflectance\" [ 0 0 0 ]\n";
  int part = 0;
  struct Mix {
    std::string name;
    size_t a = 0, b = 0;
    double amount = 0.0;
  };
  struct Scaled {
    std::string name, base;
    double fraction = 1.0;
  };
  std::vector<Mix> mixes;
  std::vector<std::pair<std::string, std::string>> shapes;  // part file, material name
  std::set<std::string> defined;
  std::vector<Scaled> scaled;
  for (const auto& [material, faces] : parts) {
    std::string name = basis_names[size_t(material.a)];
    if (material.b >= 0) {
      const double amount = material.steps * options.amount_step;
      name = "mix-" + std::to_string(vertices.bases[size_t(material.a)]) + "-" +
             std::to_string(vertices.bases[size_t(material.b)]) + "-" + Fixed(amount, 2);
      if (defined.insert(name).second) {
        mixes.push_back({name, size_t(material.a), size_t(material.b), amount});
        scene << "MakeNamedMaterial \"" << name << "\" \"string type\" \"mix\"\n    \"string materials\" [ \""
              << basis_names[size_t(material.a)] << "\" \"" << basis_names[size_t(material.b)]
              << "\" ] \"float amount\" " << Number(amount) << "\n";
      }
    }
    if (material.level < full_level) {
      // The material at a fraction of the light's scale: black picked the rest of the time.
      const double fraction = material.level * options.scale_step;
      const std::string base = name;
      name = base + "-at-" + Fixed(fraction, 2);
      if (defined.insert(name).second) {
        scaled.push_back({name, base, fraction});
        scene << "MakeNamedMaterial \"" << name
              << "\" \"string type\" \"mix\"\n    \"string materials\" [ \"unmeasured\" \"" << base
              << "\" ] \"float amount\" " << Number(fraction) << "\n";
      }
    }
    const std::string file = "part-" + std::to_string(part++) + ".ply";
    shapes.emplace_back(file, name);
    write_part(faces, file);
    scene << "AttributeBegin\n  NamedMaterial \"" << name << "\"\n  Shape \"plymesh\" \"string filename\" \"" << file
          << "\"\nAttributeEnd\n";
  }
  result.materials = int(n_bases + mixes.size() + scaled.size());
  if (!unmeasured.empty()) {
    write_part(unmeasured, "unmeasured.ply");
    shapes.emplace_back("unmeasured.ply", "unmeasured");
    scene << "AttributeBegin\n  NamedMaterial \"unmeasured\"\n  Shape \"plymesh\" \"string filename\" \"unmeasured.ply\"\n"
          << "AttributeEnd\n";
  }
  result.file = "pbrt/photo-" + std::to_string(photo) + ".pbrt";
  result.image = "photo-" + std::to_string(photo) + ".exr";
  const std::string path = (std::filesystem::path(out_dir) / result.file).string();
  std::ofstream out(path);
  out << scene.str();
  out.close();
  if (!out) ThrowError(path, "write failed (disk full?)");

  // The same scene for Mitsuba 3, its shapes the pbrt scene's parts and each group's exported Mitsuba 3
  // material (NAME.xml beside NAME.pbrt) inlined.
  std::vector<std::string> mitsuba_materials;
  for (size_t b = 0; b < n_bases; ++b) {
    const std::filesystem::path snippet =
        (std::filesystem::path(out_dir) / basis_snippets[b]).replace_extension(".xml");
    std::ifstream in(snippet);
    if (!in) {
      result.mitsuba_not_written = snippet.string() + " cannot be read";
      break;
    }
    std::stringstream text;
    text << in.rdbuf();
    mitsuba_materials.push_back(text.str());
  }
  if (result.mitsuba_not_written.empty()) {
    std::ostringstream xml;
    const std::string intensity =
        Number(result.light_scale) + ", " + Number(result.light_scale) + ", " + Number(result.light_scale);
    // Mitsuba 3's perspective camera
    // (src/sensors/perspective.cpp and perspective_projection in include/mitsuba/render/sensor.h) looks
    // down +z with +x to the image's left and +y up: the photo's camera frame turned 180 degrees about z.
    // Film position s = ((1 + x / (z t)) / 2, (1 + aspect y / (z t)) / 2) in the photo's frame with
    // t = tan(x_fov / 2), less principal_point_offset: x_fov = 2 atan(W / (2 fx)) and offset
    // (0.5 - cx / W, 0.5 - cy / H) put pixel (u, v) at u = fx x / z + cx, v = fx y / z + cy (square
    // pixels: Mitsuba has one focal length).
    const Eigen::Matrix3d world_from_camera = m.topLeftCorner<3, 3>().transpose();
    const Eigen::Vector3d centre = -world_from_camera * m.topRightCorner<3, 1>();
    Eigen::Matrix4d to_world = Eigen::Matrix4d::Identity();
    to_world.topLeftCorner<3, 3>() = world_from_camera * Eigen::Vector3d(-1.0, -1.0, 1.0).asDiagonal();
    to_world.topRightCorner<3, 1>() = centre;
    const double x_fov = 2.0 * std::atan(w / (2.0 * fx)) * 180.0 / 3.14159265358979323846;
    xml << "<!-- Mitsuba 3: photo " << photo << " of " << session.manifest_path
        << " rendered from ibrdf's measured spatially varying model,\n"
        << "     as ../pbrt/" << std::filesystem::path(result.file).filename().string()
        << " (the same parts, mixes and light; one bounce: max_depth 2).\n"
        << "     Render: mitsuba photo-" << photo << ".xml (writes photo-" << photo << ".exr). -->\n";
    if (std::abs(fy / fx - 1.0) > 1e-6) {
      xml << "<!-- The photo's pixels are not square (fy / fx = " << Number(fy / fx)
          << "): Mitsuba's camera has one focal length, fx. -->\n";
    }
    if (result.undistorted) xml << "<!-- The photo's lens distortion is not rendered: an undistorted pinhole. -->\n";
    xml << "<scene version=\"3.0.0\">\n"
        << "    <integrator type=\"path\">\n        <integer name=\"max_depth\" value=\"2\"/>\n    </integrator>\n"
        << "    <sensor type=\"perspective\">\n"
        << "        <string name=\"fov_axis\" value=\"x\"/>\n"
        << "        <float name=\"fov\" value=\"" << Number(x_fov) << "\"/>\n"
        << "        <float name=\"principal_point_offset_x\" value=\"" << Number(0.5 - cx / w) << "\"/>\n"
        << "        <float name=\"principal_point_offset_y\" value=\"" << Number(0.5 - cy / h) << "\"/>\n"
        << "        <transform name=\"to_world\">\n            <matrix value=\"";
    for (int row = 0; row < 4; ++row) {
      for (int col = 0; col < 4; ++col) xml << (row || col ? " " : "") << Number(to_world(row, col));
    }
    xml << "\"/>\n        </transform>\n"
        << "        <sampler type=\"independent\">\n            <integer name=\"sample_count\" value=\""
        << options.samples_per_pixel << "\"/>\n        </sampler>\n"
        << "        <film type=\"hdrfilm\">\n"
        << "            <integer name=\"width\" value=\"" << camera.width << "\"/>\n"
        << "            <integer name=\"height\" value=\"" << camera.height << "\"/>\n"
        << "            <string name=\"pixel_format\" value=\"rgb\"/>\n"
        << "            <rfilter type=\"box\"/>\n        </film>\n    </sensor>\n";
    switch (light.kind) {
      case Light::Kind::kPoint:
        xml << "    <emitter type=\"point\">\n        <point name=\"position\" x=\"" << Number(light.position.x())
            << "\" y=\"" << Number(light.position.y()) << "\" z=\"" << Number(light.position.z())
            << "\"/>\n        <rgb name=\"intensity\" value=\"" << intensity << "\"/>\n    </emitter>\n";
        break;
      case Light::Kind::kDirectional:
        // Mitsuba's direction is the light's travel, away from the light.
        xml << "    <emitter type=\"directional\">\n        <vector name=\"direction\" x=\""
            << Number(-light.direction.x()) << "\" y=\"" << Number(-light.direction.y()) << "\" z=\""
            << Number(-light.direction.z()) << "\"/>\n        <rgb name=\"irradiance\" value=\"" << intensity
            << "\"/>\n    </emitter>\n";
        break;
    }
    for (const std::string& text : mitsuba_materials) {
      xml << text << (text.empty() || text.back() == '\n' ? "" : "\n");
    }
    for (const Mix& mix : mixes) {
      xml << "<bsdf type=\"blendbsdf\" id=\"" << mix.name << "\">\n    <float name=\"weight\" value=\""
          << Number(mix.amount) << "\"/>\n    <ref id=\"" << basis_names[mix.a] << "\"/>\n    <ref id=\""
          << basis_names[mix.b] << "\"/>\n</bsdf>\n";
    }
    xml << "<bsdf type=\"diffuse\" id=\"unmeasured\">\n    <rgb name=\"reflectance\" value=\"0, 0, 0\"/>\n</bsdf>\n";
    for (const Scaled& material : scaled) {
      xml << "<bsdf type=\"blendbsdf\" id=\"" << material.name << "\">\n    <float name=\"weight\" value=\""
          << Number(material.fraction) << "\"/>\n    <ref id=\"unmeasured\"/>\n    <ref id=\"" << material.base
          << "\"/>\n</bsdf>\n";
    }
    for (const auto& [file, name] : shapes) {
      xml << "<shape type=\"ply\">\n    <string name=\"filename\" value=\"../pbrt/" << file << "\"/>\n    <ref id=\""
          << name << "\"/>\n</shape>\n";
    }
    xml << "</scene>\n";
    result.mitsuba_file = "mitsuba/photo-" + std::to_string(photo) + ".xml";
    std::filesystem::create_directories(std::filesystem::path(out_dir) / "mitsuba");
    const std::string xml_path = (std::filesystem::path(out_dir) / result.mitsuba_file).string();
    std::ofstream xml_out(xml_path);
    xml_out << xml.str();
    xml_out.close();
    if (!xml_out) ThrowError(xml_path, "write failed (disk full?)");
  }
  result.written = true;
  return result;
}

SceneModelRender RenderSceneModel(const Session& session, size_t photo, const std::vector<LocatedSample>& samples,
                                  const MaterialWeightsResult& weights, const std::vector<const BrdfModel*>& fits,
                                  const Eigen::Vector3d& origin, double cell_m, double light_scale,
                                  const std::string& out_dir) {
  SceneModelRender result;
  if (photo >= session.photos.size() || !session.photos[photo].camera_from_world) return result;
  if (fits.size() != weights.bases) throw InternalError("RenderSceneModel: a fit per basis");
  const std::unordered_map<uint64_t, size_t> cell_of_key = FittedCellsByKey(weights);
  const Camera& camera = session.camera;
  const Light& light = session.lights[session.photos[photo].light];
  Image sum(camera.width, camera.height, 4);
  std::vector<double> sums;
  double scene_sum = 0.0, full_sum = 0.0;
  for (const LocatedSample& located : samples) {
    const BrdfSample& s = located.sample;
    if (s.image != photo) continue;
    const auto it = cell_of_key.find(UniformityCellKey(located.point.cast<double>(), origin, cell_m));
    if (it == cell_of_key.end()) continue;
    // The scene's mix of the cell's two largest weights, scaled to the cell's sum (see the header).
    const Eigen::VectorXd& cell = weights.cells[it->second].weights;
    const auto [first, second] = LargestTwo(cell);
    const double total = cell[first] + (second >= 0 ? cell[second] : 0.0);
    if (!(total > 0.0)) continue;
    const double brightness = std::min(cell.sum(), light_scale);
    Eigen::VectorXd w = Eigen::VectorXd::Zero(cell.size());
    w[first] = brightness * cell[first] / total;
    if (second >= 0) w[second] = brightness * cell[second] / total;
    const Eigen::Vector3d wi(s.wi[0], s.wi[1], s.wi[2]), wo(s.wo[0], s.wo[1], s.wo[2]);
    if (!(wi.z() > 0.0 && wo.z() > 0.0)) continue;
    double irradiance = wi.z();  // per unit of the light's intensity or radiance
    switch (light.kind) {
      case Light::Kind::kPoint:
        irradiance /= (light.position - located.point.cast<double>()).squaredNorm();
        break;
      case Light::Kind::kDirectional:
        break;
    }
    Eigen::Vector3d radiance = Eigen::Vector3d::Zero(), full = Eigen::Vector3d::Zero();
    for (size_t b = 0; b < fits.size(); ++b) {
      const Eigen::Vector3d f = fits[b]->Eval(wi, wo);
      radiance += w[Eigen::Index(b)] * f;
      full += cell[Eigen::Index(b)] * f;
    }
    radiance *= irradiance;
    if (!radiance.allFinite() || !full.allFinite()) continue;
    sums.push_back(cell.sum());
    scene_sum += radiance.sum();
    full_sum += irradiance * full.sum();
    // The pixel centre's ray, in the undistorted pinhole's raster.
    const Eigen::Vector2d plane = camera.CamPlaneFromImage(Eigen::Vector2d(s.pixel[0] + 0.5, s.pixel[1] + 0.5));
    const double u = camera.FocalX() * plane.x() + camera.PrincipalX();
    const double v = camera.FocalY() * plane.y() + camera.PrincipalY();
    if (!(u >= 0.0 && v >= 0.0 && u < camera.width && v < camera.height)) continue;
    const int x = int(u), y = int(v);
    for (int c = 0; c < 3; ++c) sum.at(x, y, c) += float(radiance[c]);
    sum.at(x, y, 3) += 1.0f;
  }
  for (int y = 0; y < sum.height; ++y) {
    for (int x = 0; x < sum.width; ++x) {
      const float n = sum.at(x, y, 3);
      if (n == 0.0f) continue;
      for (int c = 0; c < 3; ++c) sum.at(x, y, c) /= n;
      sum.at(x, y, 3) = 1.0f;
      ++result.pixels;
    }
  }
  if (!sums.empty()) {
    result.weight_sum_p05 = Percentile(sums, 0.05);
    result.weight_sum_median = Percentile(sums, 0.5);
    result.weight_sum_p95 = Percentile(sums, 0.95);
  }
  if (scene_sum > 0.0) result.full_model_ratio = full_sum / scene_sum;
  result.image = "pbrt/photo-" + std::to_string(photo) + "-ibrdf.exr";
  std::filesystem::create_directories(std::filesystem::path(out_dir) / "pbrt");
  WriteImage((std::filesystem::path(out_dir) / result.image).string(), sum, PixelFormat::kFloat);
  result.written = true;
  return result;
}

}  // namespace ibrdf
