// JSON (the library's settings, camera and report format) to Python objects and back.
#pragma once

#include <string_view>

#include <pybind11/pybind11.h>
#include <nlohmann/json.hpp>

namespace subscan::python {

/// null, bool, numbers, strings, arrays and objects as None, bool, int, float, str, list and
/// dict.
pybind11::object toPython(const nlohmann::json& json);

/// The reverse, also for tuples, numpy scalars and numpy arrays (as nested lists). Throws
/// ValueError naming `what` for anything JSON cannot hold (sets, objects, non-str keys).
nlohmann::json toJson(const pybind11::handle& object, std::string_view what);

}  // namespace subscan::python
