// The `ibrdf` Python module (docs/python.md): its exceptions, the session, the JSON conversion, and
// RunLong, the way every long call runs. Brdf and the stages are bound in their own files.
#include <dlfcn.h>

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <mutex>
#include <string>
#include <thread>

#include <nlohmann/json.hpp>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "core/error.h"
#include "core/logging.h"
#include "core/progress_observer.h"
#include "core/session.h"
#include "core/version.h"
#include "python/bindings.h"

namespace ibrdf::python {

py::object ToPython(const nlohmann::json& value) {
  switch (value.type()) {
    case nlohmann::json::value_t::null:
    case nlohmann::json::value_t::discarded:
      return py::none();
    case nlohmann::json::value_t::boolean:
      return py::bool_(value.get<bool>());
    case nlohmann::json::value_t::number_integer:
      return py::int_(value.get<int64_t>());
    case nlohmann::json::value_t::number_unsigned:
      return py::int_(value.get<uint64_t>());
    case nlohmann::json::value_t::number_float:
      return py::float_(value.get<double>());
    case nlohmann::json::value_t::string:
      return py::str(value.get_ref<const std::string&>());
    case nlohmann::json::value_t::binary:
      return py::bytes(reinterpret_cast<const char*>(value.get_binary().data()), value.get_binary().size());
    case nlohmann::json::value_t::array: {
      py::list list;
      for (const nlohmann::json& item : value) list.append(ToPython(item));
      return std::move(list);
    }
    case nlohmann::json::value_t::object: {
      py::dict dict;
      for (const auto& [key, item] : value.items()) dict[py::str(key)] = ToPython(item);
      return std::move(dict);
    }
  }
  return py::none();
}

namespace {

std::atomic<bool> g_stop_requested{false};

// What the observer saw last, for the waiting thread to report.
struct ProgressState {
  std::mutex mutex;
  std::string label;
  uint64_t done = 0, total = 0;
  bool changed = false;
};

}  // namespace

bool StopRequested() { return g_stop_requested.load(); }

void RunLong(const std::function<void()>& work, const py::object& progress) {
  // One long call at a time: the progress observer is process-wide (calls from other Python threads wait).
  static std::mutex one_at_a_time;
  std::unique_lock<std::mutex> turn(one_at_a_time, std::defer_lock);
  {
    py::gil_scoped_release release;
    turn.lock();
  }
  auto state = std::make_shared<ProgressState>();
  g_stop_requested = false;
  SetProgressObserver([state](const std::string& label, uint64_t done, uint64_t total) {
    {
      std::lock_guard<std::mutex> lock(state->mutex);
      state->label = label;
      state->done = done;
      state->total = total;
      state->changed = true;
    }
    return !g_stop_requested.load();
  });
  std::mutex mutex;
  std::condition_variable finished;
  bool ended = false;
  std::exception_ptr error;
  std::thread worker;
  {
    py::gil_scoped_release release;
    worker = std::thread([&] {
      try {
        work();
      } catch (...) {
        error = std::current_exception();
      }
      std::lock_guard<std::mutex> lock(mutex);
      ended = true;
      finished.notify_all();
    });
  }
  // Stops the work and waits for it, for a Python exception raised here (Ctrl-C, the callback's own).
  const auto stop = [&] {
    g_stop_requested = true;
    py::gil_scoped_release release;
    worker.join();
    SetProgressObserver({});
  };
  const auto report = [&] {
    if (progress.is_none()) return;
    std::string label;
    uint64_t done = 0, total = 0;
    {
      std::lock_guard<std::mutex> lock(state->mutex);
      if (!state->changed) return;
      state->changed = false;
      label = state->label;
      done = state->done;
      total = state->total;
    }
    progress(label, done, total);
  };
  while (true) {
    {
      py::gil_scoped_release release;
      std::unique_lock<std::mutex> lock(mutex);
      finished.wait_for(lock, std::chrono::milliseconds(100), [&] { return ended; });
      if (ended) break;
    }
    if (PyErr_CheckSignals() != 0) {
      stop();
      throw py::error_already_set();
    }
    try {
      report();
    } catch (...) {
      stop();
      throw;
    }
  }
  {
    py::gil_scoped_release release;
    worker.join();
  }
  SetProgressObserver({});
  if (error) std::rethrow_exception(error);
  report();  // the last step, so that a callback sees done == total
}

namespace {

// The folder this module was loaded from.
std::filesystem::path ModuleFolder() {
  Dl_info info{};
  if (dladdr(reinterpret_cast<void*>(&ModuleFolder), &info) == 0 || !info.dli_fname) return {};
  std::error_code error;
  const std::filesystem::path path = std::filesystem::canonical(info.dli_fname, error);
  return error ? std::filesystem::path() : path.parent_path();
}

// The `ibrdf` tool that `run` launches (and whose build ids key its stamps, workflow/build_id.h), as the
// front end would set it: IBRDF_TOOL; else the build tree's tool for the build tree's module, the
// installed tool for the installed one (and the installed OpenImageIO module, core/image_io.cc, which
// looks beside the running binary, here Python's).
void LocateTool() {
  const std::filesystem::path folder = ModuleFolder();
  std::error_code error;
  if (folder.empty() || std::filesystem::equivalent(folder, IBRDF_PYTHON_BUILD_DIR, error)) {
    setenv("IBRDF_TOOL", IBRDF_PYTHON_BUILD_TOOL, 0);
    return;
  }
  const std::filesystem::path prefix = (folder / IBRDF_PYTHON_TO_PREFIX).lexically_normal();
  setenv("IBRDF_TOOL", (prefix / "bin" / "ibrdf").c_str(), 0);
  setenv("IBRDF_OIIO_MODULE", (prefix / "lib" / "ibrdf" / "libibrdf_oiio.so").c_str(), 0);
}

// The CLI's message for a path the file system refused (apps/command_main.cc).
std::string FilesystemMessage(const std::filesystem::filesystem_error& e) {
  return (e.path1().empty() ? std::string() : e.path1().string() + ": ") + e.code().message();
}

// Raises `type` with `message`, whose bytes that are not UTF-8 (a corrupt file's field name quoted in
// it) are kept as \x escapes rather than lost.
void SetError(PyObject* type, const std::string& message) {
  PyObject* text = PyUnicode_DecodeUTF8(message.data(), Py_ssize_t(message.size()), "backslashreplace");
  PyErr_SetObject(type, text);
  Py_XDECREF(text);
}

}  // namespace

void DefineModule(py::module_& m) {
  m.doc() = "ibrdf: image-based BRDF measurement (after Marschner et al. 1999), from Python (docs/python.md).";
  m.attr("__version__") = kIbrdfVersion;
  LocateTool();
  // Quiet by default: stage lines and summaries go to stderr only when asked (set_verbosity).
  SetVerbosity(0);

  // The CLI prints "ibrdf: error: " and the message of these; here the message is the exception's.
  // Never released, as SampleDtype's (python/stage_bindings.cc).
  static py::exception<Error>& error = *new py::exception<Error>(m, "Error");
  error.doc() = "Bad input: the message names the file and the field or line, as the CLI's error does.";
  static py::exception<InternalError>& internal_error = *new py::exception<InternalError>(m, "InternalError");
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const Interrupted& e) {
      SetError(PyExc_KeyboardInterrupt, e.what());
    } catch (const Error& e) {
      SetError(error.ptr(), e.what());
    } catch (const std::filesystem::filesystem_error& e) {
      SetError(error.ptr(), FilesystemMessage(e));
    } catch (const InternalError& e) {
      SetError(internal_error.ptr(), std::string(e.what()) + " (please report it)");
    }
  });

  m.def("set_verbosity", &SetVerbosity, py::arg("level"),
        "What the library prints to stderr: 0 errors only (the module's default), 1 stage lines and summaries, 2\n"
        "progress bars too (the CLI's default).");
  m.def("tool_path", [] { return std::string(std::getenv("IBRDF_TOOL") ? std::getenv("IBRDF_TOOL") : ""); },
        "The `ibrdf` tool that run() launches (IBRDF_TOOL).");

  py::class_<Session>(m, "Session", "A measurement session: session.json and the files it names (docs/session-format.md).")
      .def_static("load", &Session::Load, py::arg("path"),
                  "Reads and validates a manifest (session.json, or the folder holding it); ibrdf.Error naming\n"
                  "the manifest and the field's JSON pointer otherwise, as every CLI stage does.")
      .def("validate", &Session::CheckPhotos,
           "Opens every photo's header (and its mask's) and checks its size against the camera.")
      .def(
          "save",
          [](const Session& session, const std::string& dir) {
            std::filesystem::create_directories(dir);
            return session.SaveRebased(dir);
          },
          py::arg("dir"),
          "Writes the manifest to DIR/session.json (created; paths rewritten relative to DIR); returns its path.")
      .def("to_json", [](const Session& session) { return ToPython(session.ToJson()); }, "The manifest as a dict.")
      .def("input_files", &Session::InputFiles, "Every file the session references, absolute.")
      .def("photo_path", &Session::PhotoPath, py::arg("i"), "The path of photo i.")
      .def_readonly("name", &Session::name)
      .def_readonly("directory", &Session::directory)
      .def_readonly("manifest_path", &Session::manifest_path)
      .def_property_readonly("sample_kind", [](const Session& session) { return SampleKindName(session.sample.kind); })
      .def_property_readonly("num_photos", [](const Session& session) { return session.photos.size(); })
      .def_property_readonly("image_size",
                             [](const Session& session) { return py::make_tuple(session.camera.width, session.camera.height); })
      .def("__repr__", [](const Session& session) {
        return "<ibrdf.Session " + session.name + ": " + std::to_string(session.photos.size()) + " photos, " +
               SampleKindName(session.sample.kind) + ">";
      });

  BindBrdf(m);
  BindStages(m);
}

}  // namespace ibrdf::python

PYBIND11_MODULE(ibrdf, m) { ibrdf::python::DefineModule(m); }
