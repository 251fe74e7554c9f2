// The stage functions of the `ibrdf` module, each the call its subcommand makes (apps/*_command.cc)
// with the subcommand's options as a class whose fields are keyword arguments: derender, check, compare,
// reconstruct and run; and the sample files as numpy structured arrays (samples.npy's dtype).
#include <cstring>
#include <memory>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <tbb/global_control.h>

#include "core/error.h"
#include "core/json_reader.h"
#include "core/logging.h"
#include "core/merl_brdf.h"
#include "core/output_guard.h"
#include "core/progress_observer.h"
#include "core/sample_file.h"
#include "core/session.h"
#include "core/version.h"
#include "derender/derenderer.h"
#include "python/bindings.h"
#include "reconstruct/consistency.h"
#include "reconstruct/prediction_check.h"
#include "reconstruct/reconstruction_stage.h"
#include "reconstruct/truth_comparison.h"
#include "workflow/run_folder.h"

namespace ibrdf::python {
namespace {

// samples.npy's dtype (core/sample_file.h), from the header text the files are written with.
py::dtype SampleDtype() {
  // Never released: a static Python object would be released after the interpreter has ended.
  static const py::object* dtype = new py::object(py::module_::import("numpy.lib.format")
                                                      .attr("descr_to_dtype")(py::module_::import("ast").attr("literal_eval")(BrdfSampleDtype())));
  return dtype->cast<py::dtype>();
}

// The samples as a structured array that owns them: no copy.
py::array ToArray(std::vector<BrdfSample> samples) {
  auto* owned = new std::vector<BrdfSample>(std::move(samples));
  py::capsule owner(owned, [](void* p) { delete static_cast<std::vector<BrdfSample>*>(p); });
  return py::array(SampleDtype(), {py::ssize_t(owned->size())}, {py::ssize_t(sizeof(BrdfSample))}, owned->data(),
                   owner);
}

// A sample file's path, or a structured array of samples.npy's dtype (copied: the stages take a vector).
std::vector<BrdfSample> SamplesFrom(const py::object& samples) {
  if (py::isinstance<py::str>(samples)) return ReadSamples(samples.cast<std::string>());
  const py::array array = py::array::ensure(samples);
  if (!array || !array.dtype().equal(SampleDtype()) || array.ndim() != 1) {
    throw py::type_error("samples: expected a sample file's path or a 1-D array of samples.npy's dtype (ibrdf.sample_dtype())");
  }
  const py::array contiguous = py::array::ensure(array, py::array::c_style);
  std::vector<BrdfSample> out(size_t(contiguous.shape(0)));
  if (!out.empty()) std::memcpy(out.data(), contiguous.data(), out.size() * sizeof(BrdfSample));
  return out;
}

// A session object or a manifest's path.
Session SessionFrom(const py::object& session) {
  if (py::isinstance<Session>(session)) return session.cast<Session>();
  return Session::Load(py::str(session).cast<std::string>());
}

// `defaults` with each keyword argument set as an attribute (an unknown name: AttributeError), checked.
template <typename Options>
Options WithKeywords(const Options& defaults, const py::kwargs& keywords) {
  py::object object = py::cast(defaults);
  for (const auto& [name, value] : keywords) py::setattr(object, name, value);
  Options options = object.cast<Options>();
  std::string why;
  if (!options.Check(&why)) throw py::value_error("bad value: " + why);
  return options;
}

// The options struct's fields as read-write attributes and its keyword constructor.
template <typename Options>
py::class_<Options> OptionsClass(py::module_& m, const char* name, const char* doc) {
  py::class_<Options> c(m, name, doc);
  c.def(py::init([](const py::kwargs& keywords) {
          py::object object = py::cast(Options());
          for (const auto& [key, value] : keywords) py::setattr(object, key, value);
          return object.cast<Options>();
        }))
      .def("check", [](const Options& options) {
        std::string why;
        if (!options.Check(&why)) throw py::value_error("bad value: " + why);
      });
  return c;
}

py::object Derender(const py::object& session_arg, const py::object& out, bool overwrite, bool with_summary,
                    const py::object& progress, const py::kwargs& keywords) {
  const DerenderOptions options = WithKeywords(DerenderOptions(), keywords);
  const Session session = SessionFrom(session_arg);
  DerenderResult result;
  if (!out.is_none()) {
    const std::string path = py::str(out);
    std::vector<std::string> inputs = SessionInputs(session);
    if (!session.sample.mesh_file.empty()) inputs.push_back(session.AbsolutePath(session.sample.mesh_file) + ".json");
    RequireWritableOutputs(path, {{SidecarPath(path), "ibrdf-samples"}}, overwrite, inputs);
    // The stage streams its samples to the file; the array returned is the file's.
    RunLong([&] { result.summary = DerenderToFile(session, options, path); }, progress);
    result.samples = ReadSamples(path);
  } else {
    RunLong([&] { result = ibrdf::Derender(session, options); }, progress);
  }
  const nlohmann::json summary = DerenderSidecar(session, options, result.summary);
  py::array samples = ToArray(std::move(result.samples));
  if (with_summary) return py::make_tuple(samples, ToPython(summary));
  return std::move(samples);
}

py::object Check(const py::object& samples_arg, const py::object& out, bool overwrite, bool regression,
                 int held_out, const py::object& progress, const py::kwargs& keywords) {
  const ConsistencyOptions options = WithKeywords(ConsistencyOptions(), keywords);
  PredictionCheckOptions prediction;
  prediction.held_out_photos = held_out;
  std::string why;
  if (regression && !prediction.Check(&why)) throw py::value_error("bad value: " + why);
  if (!out.is_none()) {
    std::vector<std::string> inputs;
    if (py::isinstance<py::str>(samples_arg)) {
      inputs = {samples_arg.cast<std::string>(), SidecarPath(samples_arg.cast<std::string>())};
    }
    RequireWritableOutput(py::str(out), overwrite, inputs);
  }
  const std::vector<BrdfSample> samples = SamplesFrom(samples_arg);
  nlohmann::json report;
  RunLong([&] { report = CheckSamples(samples, options, regression ? &prediction : nullptr); }, progress);
  if (!out.is_none()) WriteJsonFile(py::str(out), report);
  return ToPython(report);
}

py::object Compare(const std::string& samples, const std::string& truth_arg, size_t lookups, const py::object& out,
                   bool overwrite) {
  if (IsMerlPath(samples) && truth_arg.empty()) ThrowError(samples, "a MERL table has no session: pass --truth");
  const std::string truth = truth_arg.empty() ? TruthPathFromSidecar(samples) : truth_arg;
  if (!out.is_none()) RequireWritableOutput(py::str(out), overwrite, {samples, SidecarPath(samples), truth});
  CompareOutcome outcome;
  RunLong([&] { outcome = CompareFileWithTruth(samples, truth, lookups); }, py::none());
  if (!out.is_none()) WriteJsonFile(py::str(out), outcome.json);
  return ToPython(outcome.json);
}

py::object Reconstruct(const py::object& samples_arg, const std::string& out, bool overwrite,
                       const py::object& options_arg, const py::object& progress, const py::kwargs& keywords) {
  ReconstructOptions defaults =
      options_arg.is_none() ? ReconstructOptions() : options_arg.cast<ReconstructOptions>();
  defaults.overwrite = overwrite;
  const ReconstructOptions options = WithKeywords(defaults, keywords);
  ReconstructResult result;
  if (py::isinstance<py::str>(samples_arg)) {
    const std::string path = samples_arg.cast<std::string>();
    RequireWritableOutput(out, options.overwrite, {path, SidecarPath(path), options.truth_file, options.eval_file});
    RunLong([&] { result = ReconstructFile(path, options, out); }, progress);
  } else {
    RequireWritableOutput(out, options.overwrite, {options.truth_file, options.eval_file});
    const std::vector<BrdfSample> samples = SamplesFrom(samples_arg);
    RunLong([&] { result = ibrdf::Reconstruct(samples, options, out); }, progress);
  }
  return ToPython(result.summary);
}

py::object Run(const std::string& input, const std::string& out, bool overwrite, const py::object& progress,
               const py::kwargs& keywords) {
  const MeasurementOptions options = WithKeywords(MeasurementOptions(), keywords);
  const int threads = int(tbb::global_control::active_value(tbb::global_control::max_allowed_parallelism));
  const StageLauncher child = ChildStageLauncher(threads);
  // The stages are child processes: they see a terminal's Ctrl-C themselves; a stop asked of this
  // process alone takes effect when the running stage ends.
  const StageLauncher launch = [child](const std::string& name, const std::vector<std::string>& arguments,
                                       const std::string& log_path) {
    if (StopRequested()) throw Interrupted(name + ": interrupted");
    const int status = child(name, arguments, log_path);
    if (StopRequested()) throw Interrupted(name + ": interrupted");
    return status;
  };
  nlohmann::json summary;
  RunLong(
      [&] {
        const Timer wall;
        summary = RunInFolder(input, out, options, overwrite, launch, kIbrdfVersionLine, wall);
      },
      progress);
  return ToPython(summary);
}

}  // namespace

void BindStages(py::module_& m) {
  m.def("sample_dtype", &SampleDtype, "samples.npy's structured dtype (docs/sample-format.md).");
  m.def("read_samples", [](const std::string& path) { return ToArray(ReadSamples(path)); }, py::arg("path"),
        "A sample file (.npy of `ibrdf derender`, versions 1 and 2) as a structured array, checked as every stage\n"
        "checks it (ibrdf.Error naming the file and the first invalid sample). The array owns the data read.");

  OptionsClass<DerenderOptions>(m, "DerenderOptions", "derender's options (derender/derenderer.h); keyword arguments of derender()")
      .def_readwrite("max_theta_i_deg", &DerenderOptions::max_theta_i_deg)
      .def_readwrite("max_theta_e_deg", &DerenderOptions::max_theta_e_deg)
      .def_readwrite("min_signal", &DerenderOptions::min_signal)
      .def_readwrite("pixel_stride", &DerenderOptions::pixel_stride)
      .def_property(
          "visibility",
          [](const DerenderOptions& o) -> py::object {
            if (!o.visibility) return py::none();
            return py::str(VisibilityName(*o.visibility));
          },
          [](DerenderOptions& o, const py::object& value) {
            if (value.is_none()) {
              o.visibility.reset();
              return;
            }
            Visibility visibility;
            if (!VisibilityFromName(py::str(value), &visibility)) {
              throw py::value_error("visibility: expected \"auto\", \"on\", \"off\" or None");
            }
            o.visibility = visibility;
          })
      .def_readwrite("mask_mixed_pixels", &DerenderOptions::mask_mixed_pixels)
      .def_readwrite("mixed_pixel_depth_factor", &DerenderOptions::mixed_pixel_depth_factor)
      .def_readwrite("max_normal_fit_rms_m", &DerenderOptions::max_normal_fit_rms_m)
      .def_readwrite("min_fit_neighbours", &DerenderOptions::min_fit_neighbours)
      .def_readwrite("shadow_edge_deg", &DerenderOptions::shadow_edge_deg)
      .def_readwrite("shadow_edge_rays", &DerenderOptions::shadow_edge_rays);
  m.def("derender", &Derender, py::arg("session"), py::kw_only(), py::arg("out") = py::none(),
        py::arg("overwrite") = false, py::arg("with_summary") = false, py::arg("progress") = py::none(),
        "`ibrdf derender`: every pixel of every photo of a session (an ibrdf.Session or its path) to a BRDF\n"
        "sample. Returns the samples as a structured array of samples.npy's dtype (no copy); with\n"
        "with_summary=True, (samples, the sidecar's dict). With out=PATH also writes PATH and PATH.json, as the CLI.\n"
        "Keyword arguments: DerenderOptions' fields (max_theta_i_deg=70, pixel_stride=2, ...).");

  OptionsClass<ConsistencyOptions>(m, "CheckOptions", "check's options (reconstruct/consistency.h); keyword arguments of check()")
      .def_readwrite("theta_bin_deg", &ConsistencyOptions::theta_bin_deg)
      .def_readwrite("phi_bin_deg", &ConsistencyOptions::phi_bin_deg)
      .def_readwrite("min_samples_per_bin", &ConsistencyOptions::min_samples_per_bin)
      .def_readwrite("max_theta_deg", &ConsistencyOptions::max_theta_deg)
      .def_readwrite("match_deg", &ConsistencyOptions::match_deg)
      .def_readwrite("worst_bins", &ConsistencyOptions::worst_bins);
  m.def("check", &Check, py::arg("samples"), py::kw_only(), py::arg("out") = py::none(), py::arg("overwrite") = false,
        py::arg("regression") = false, py::arg("held_out") = 3, py::arg("progress") = py::none(),
        "`ibrdf check`: reciprocity and bilateral symmetry of samples (a sample file's path or a structured\n"
        "array); returns the report (consistency.json) as a dict, written to out= if given.");

  m.def("compare", &Compare, py::arg("samples"), py::kw_only(), py::arg("truth") = "", py::arg("lookups") = 200000,
        py::arg("out") = py::none(), py::arg("overwrite") = false,
        "`ibrdf compare`: a sample file (or a MERL table) against the truth (default: the samples' session's\n"
        "truth.json); returns the figures as a dict, written to out= if given.");

  py::class_<LocalRegressionOptions>(m, "RegressionOptions", "The local regression's kernel (reconstruct/local_regression.h)")
      .def(py::init<>())
      .def_readwrite("degree", &LocalRegressionOptions::degree)
      .def_readwrite("radius_h_deg", &LocalRegressionOptions::radius_h_deg)
      .def_readwrite("radius_d_deg", &LocalRegressionOptions::radius_d_deg)
      .def_readwrite("fold_reciprocity", &LocalRegressionOptions::fold_reciprocity)
      .def_readwrite("fold_bilateral", &LocalRegressionOptions::fold_bilateral)
      .def_readwrite("log_space", &LocalRegressionOptions::log_space)
      .def_readwrite("bin_fraction_h", &LocalRegressionOptions::bin_fraction_h)
      .def_readwrite("bin_fraction_d", &LocalRegressionOptions::bin_fraction_d);
  py::class_<TabulateOptions>(m, "TabulateOptions", "The MERL table's limits (reconstruct/merl_table.h)")
      .def(py::init<>())
      .def_readwrite("max_theta_deg", &TabulateOptions::max_theta_deg)
      .def_readwrite("min_effective_samples", &TabulateOptions::min_effective_samples);
  py::class_<ModelFitOptions>(m, "FitOptions", "The Lafortune and GGX fits (reconstruct/model_fit.h)")
      .def(py::init<>())
      .def_readwrite("lafortune_lobes", &ModelFitOptions::lafortune_lobes)
      .def_readwrite("max_samples", &ModelFitOptions::max_samples)
      .def_readwrite("start_samples", &ModelFitOptions::start_samples);
  OptionsClass<ReconstructOptions>(m, "ReconstructOptions",
                                   "reconstruct's options (reconstruct/reconstruction_stage.h); keyword arguments of reconstruct()")
      .def_readwrite("regression", &ReconstructOptions::regression)
      .def_readwrite("tabulate", &ReconstructOptions::tabulate)
      .def_readwrite("fit", &ReconstructOptions::fit)
      .def_readwrite("fits", &ReconstructOptions::fits)
      .def_readwrite("bsdf", &ReconstructOptions::bsdf)
      .def_readwrite("eval_file", &ReconstructOptions::eval_file)
      .def_readwrite("truth_file", &ReconstructOptions::truth_file)
      .def_readwrite("name", &ReconstructOptions::name);
  m.def("reconstruct", &Reconstruct, py::arg("samples"), py::arg("out"), py::kw_only(), py::arg("overwrite") = false,
        py::arg("options") = py::none(), py::arg("progress") = py::none(),
        "`ibrdf reconstruct`: samples (a sample file's path or a structured array) to the folder out (brdf.binary,\n"
        "fits, NAME.bsdf, summary.json); returns summary.json as a dict. Keyword arguments: ReconstructOptions'\n"
        "fields (fits=False, name=..., regression=RegressionOptions(...)); options= a ReconstructOptions.");

  OptionsClass<MeasurementOptions>(m, "RunOptions", "run's options (workflow/measurement.h); keyword arguments of run()")
      .def_readwrite("pixel_stride", &MeasurementOptions::pixel_stride)
      .def_readwrite("degree", &MeasurementOptions::degree)
      .def_readwrite("radius_h_deg", &MeasurementOptions::radius_h_deg)
      .def_readwrite("radius_d_deg", &MeasurementOptions::radius_d_deg)
      .def_readwrite("fits", &MeasurementOptions::fits)
      .def_readwrite("check_regression", &MeasurementOptions::check_regression)
      .def_readwrite("report", &MeasurementOptions::report)
      .def_readwrite("force", &MeasurementOptions::force)
      .def_readwrite("concurrent_sample_stages", &MeasurementOptions::concurrent_sample_stages)
      .def_readwrite("stop_after", &MeasurementOptions::stop_after)
      .def_readwrite("derender_args", &MeasurementOptions::derender_args)
      .def_readwrite("check_args", &MeasurementOptions::check_args)
      .def_readwrite("reconstruct_args", &MeasurementOptions::reconstruct_args)
      .def_readwrite("report_args", &MeasurementOptions::report_args);
  m.def("run", &Run, py::arg("input"), py::arg("out"), py::kw_only(), py::arg("overwrite") = false,
        py::arg("progress") = py::none(),
        "`ibrdf run`: the whole workflow of a recipe folder or a session into the run folder out, each stage a\n"
        "child `ibrdf` process (ibrdf.tool_path()), resumed when up to date; returns summary.json as a dict.\n"
        "Keyword arguments: RunOptions' fields (pixel_stride=2, fits=False, stop_after=\"derender\", ...).");
}

}  // namespace ibrdf::python
