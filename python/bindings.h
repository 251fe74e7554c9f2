// The pieces the `ibrdf` Python module's files share (python/module.cc defines the module): the
// conversions of ibrdf's JSON and errors to Python, and how a long library call runs (without the
// GIL, with progress and Ctrl-C). Only python/ includes it.
#pragma once

#include <functional>

#include <nlohmann/json.hpp>
#include <pybind11/pybind11.h>

namespace ibrdf::python {

namespace py = pybind11;

// A JSON value as Python objects: dict, list, str, int, float, bool, None.
py::object ToPython(const nlohmann::json& value);

// Runs `work` on a worker thread without the GIL while this thread waits for it: every 0.1 s it
// checks for signals (Ctrl-C raises KeyboardInterrupt here: the work is asked to stop at its next
// progress-bar step, core/progress_observer.h, and joined first) and calls `progress(label, done,
// total)` when a progress bar of the library has advanced (None: no callback). An exception of the
// work is rethrown here, so the module's translators turn it into the Python exception. Calls from
// several Python threads run one after another.
void RunLong(const std::function<void()>& work, const py::object& progress);

// True once Ctrl-C asked the running RunLong work to stop: for work that has no progress bar to stop
// at (`run`'s child stages), checked between its steps.
bool StopRequested();

// Adds Brdf (python/brdf_bindings.cc) and the stage functions with their options classes
// (python/stage_bindings.cc) to the module.
void BindBrdf(py::module_& m);
void BindStages(py::module_& m);

}  // namespace ibrdf::python
