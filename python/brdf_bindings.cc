// ibrdf.Brdf: a material (core/brdf_model.h LoadMaterial: a material or fit file, a MERL table, an RGL
// .bsdf; or a synthetic session's truth.json) evaluated over numpy arrays of directions or angles.
#include <memory>
#include <string>

#include <nlohmann/json.hpp>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "core/brdf_coords.h"
#include "core/brdf_model.h"
#include "core/merl_brdf.h"
#include "core/merl_format.h"
#include "python/bindings.h"
#include "reconstruct/truth_comparison.h"

namespace ibrdf::python {
namespace {

using Directions = py::array_t<double, py::array::c_style | py::array::forcecast>;

// Pairs evaluated per task: enough to hide the scheduling, few enough to share 1e5 pairs among threads.
constexpr size_t kGrain = 2048;

// An (N, 3) array's row count, or a ValueError naming the argument.
size_t Rows(const Directions& array, const char* name) {
  if (array.ndim() != 2 || array.shape(1) != 3) {
    throw py::value_error(std::string(name) + ": expected an (N, 3) array of unit directions, local frame (z = normal)");
  }
  return size_t(array.shape(0));
}

// f(wi[n], wo[n]) for every row: (N, 3) RGB, 1/sr, 0 below the horizon; the rows across threads
// without the GIL.
py::array_t<double> Eval(const BrdfModel& brdf, const Directions& wi, const Directions& wo) {
  const size_t n = Rows(wi, "wi");
  if (Rows(wo, "wo") != n) throw py::value_error("wi and wo: expected the same number of rows");
  py::array_t<double> out({py::ssize_t(n), py::ssize_t(3)});
  const double* in_i = wi.data();
  const double* in_o = wo.data();
  double* f = out.mutable_data();
  {
    py::gil_scoped_release release;
    tbb::parallel_for(tbb::blocked_range<size_t>(0, n, kGrain), [&](const tbb::blocked_range<size_t>& rows) {
      for (size_t r = rows.begin(); r != rows.end(); ++r) {
        const Eigen::Map<const Eigen::Vector3d> a(in_i + 3 * r), b(in_o + 3 * r);
        Eigen::Map<Eigen::Vector3d>(f + 3 * r) = brdf.Eval(a, b);
      }
    });
  }
  return out;
}

// f at (theta_i, theta_o, phi_d) (radians; phi_d = phi_o - phi_i), broadcast together: shape + (3,).
py::array_t<double> EvalAngles(const BrdfModel& brdf, const py::object& theta_i, const py::object& theta_o,
                               const py::object& phi_d) {
  const py::tuple arrays = py::module_::import("numpy").attr("broadcast_arrays")(theta_i, theta_o, phi_d);
  const Directions ti = arrays[0].cast<Directions>(), to = arrays[1].cast<Directions>(),
                   pd = arrays[2].cast<Directions>();
  std::vector<py::ssize_t> shape(ti.shape(), ti.shape() + ti.ndim());
  shape.push_back(3);
  py::array_t<double> out(shape);
  const size_t n = size_t(ti.size());
  const double *a = ti.data(), *b = to.data(), *c = pd.data();
  double* f = out.mutable_data();
  {
    py::gil_scoped_release release;
    tbb::parallel_for(tbb::blocked_range<size_t>(0, n, kGrain), [&](const tbb::blocked_range<size_t>& rows) {
      for (size_t r = rows.begin(); r != rows.end(); ++r) {
        Eigen::Vector3d wi, wo;
        FromIsotropic({a[r], b[r], c[r]}, &wi, &wo);
        Eigen::Map<Eigen::Vector3d>(f + 3 * r) = brdf.Eval(wi, wo);
      }
    });
  }
  return out;
}

}  // namespace

void BindBrdf(py::module_& m) {
  py::class_<BrdfModel, std::shared_ptr<BrdfModel>>(
      m, "Brdf",
      "A material: f(wi, wo), RGB in 1/sr, isotropic, in the local frame (z = normal), 0 below the horizon.")
      .def_static(
          "load", [](const std::string& path) { return std::shared_ptr<BrdfModel>(LoadMaterial(path)); },
          py::arg("path"),
          "Reads a material or fit file (.json: lambertian, lafortune, ggx, merl, rgl_bsdf; a reconstruction's\n"
          "lafortune.json or ggx.json), a MERL table (.binary) or an RGL tensor file (.bsdf). Raises ibrdf.Error\n"
          "naming the file and field, as the CLI does.")
      .def_static(
          "load_truth", [](const std::string& path) { return std::shared_ptr<BrdfModel>(LoadTruthFile(path)); },
          py::arg("path"), "Reads the truth of a synthetic session (truth.json), a material file or a MERL table.")
      .def("eval", &Eval, py::arg("wi"), py::arg("wo"),
           "f(wi[n], wo[n]) for (N, 3) arrays of unit directions (towards the light, towards the camera): (N, 3)\n"
           "RGB. float64 C-ordered input is read in place; any other is converted (a copy). Threads, no GIL.")
      .def("eval_angles", &EvalAngles, py::arg("theta_i"), py::arg("theta_o"), py::arg("phi_d"),
           "f at angles in radians (phi_d = phi_o - phi_i), numpy-broadcast together: their shape + (3,).")
      .def_property_readonly("model", &BrdfModel::ModelName, "\"lambertian\", \"lafortune\", \"ggx\", \"merl\" or \"rgl_bsdf\"")
      .def("to_json", [](const BrdfModel& brdf) { return ToPython(brdf.ToJson()); },
           "The material file's JSON as a dict (round-trips through a material file).")
      .def_property_readonly(
          "table",
          [](const BrdfModel& brdf) -> py::object {
            const auto* merl = dynamic_cast<const MerlBrdf*>(&brdf);
            if (!merl) return py::none();
            py::array_t<double> cells({py::ssize_t(kMerlCells), py::ssize_t(3)});
            for (size_t flat = 0; flat < kMerlCells; ++flat) {
              Eigen::Map<Eigen::Vector3d>(cells.mutable_data(flat, 0)) = merl->table().Cell(flat);
            }
            return cells.attr("reshape")(kMerlThetaH, kMerlThetaD, kMerlPhiD, 3);
          },
          "A MERL table's cells, (90, 90, 180, 3) RGB in 1/sr (theta_h, theta_d, phi_d), negative where it has no\n"
          "data; a copy, since the file stores channel-major floats scaled per channel. None for other models.")
      .def("__repr__", [](const BrdfModel& brdf) { return "<ibrdf.Brdf " + brdf.ModelName() + ">"; });
}

}  // namespace ibrdf::python
