#include "python/JsonConversion.h"

#include <string>

#include <fmt/format.h>
#include <pybind11/numpy.h>

namespace py = pybind11;

namespace subscan::python {

py::object toPython(const nlohmann::json& json) {
    switch (json.type()) {
        case nlohmann::json::value_t::null:
            return py::none();
        case nlohmann::json::value_t::boolean:
            return py::bool_(json.get<bool>());
        case nlohmann::json::value_t::number_integer:
            return py::int_(json.get<std::int64_t>());
        case nlohmann::json::value_t::number_unsigned:
            return py::int_(json.get<std::uint64_t>());
        case nlohmann::json::value_t::number_float:
            return py::float_(json.get<double>());
        case nlohmann::json::value_t::string:
            return py::str(json.get_ref<const std::string&>());
        case nlohmann::json::value_t::array: {
            py::list list;
            for (const nlohmann::json& item : json) {
                list.append(toPython(item));
            }
            return list;
        }
        case nlohmann::json::value_t::object: {
            py::dict dict;
            for (const auto& [key, value] : json.items()) {
                dict[py::str(key)] = toPython(value);
            }
            return dict;
        }
        default:  // binary and discarded values: the library never makes them
            return py::none();
    }
}

nlohmann::json toJson(const py::handle& object, std::string_view what) {
    if (object.is_none()) {
        return nullptr;
    }
    // bool before int: Python's bool is an int.
    if (py::isinstance<py::bool_>(object)) {
        return object.cast<bool>();
    }
    if (py::isinstance<py::int_>(object)) {
        try {
            return object.cast<std::int64_t>();
        } catch (const py::cast_error&) {
            throw py::value_error(fmt::format("{}: the integer {} is too large", what,
                                              py::str(object).cast<std::string>()));
        }
    }
    if (py::isinstance<py::float_>(object)) {
        return object.cast<double>();
    }
    if (py::isinstance<py::str>(object)) {
        return object.cast<std::string>();
    }
    if (py::isinstance<py::dict>(object)) {
        nlohmann::json json = nlohmann::json::object();
        for (const auto& [key, value] : object.cast<py::dict>()) {
            if (!py::isinstance<py::str>(key)) {
                throw py::value_error(fmt::format("{}: the key {} is not a string", what,
                                                  py::repr(key).cast<std::string>()));
            }
            json[key.cast<std::string>()] = toJson(value, what);
        }
        return json;
    }
    if (py::isinstance<py::list>(object) || py::isinstance<py::tuple>(object)) {
        nlohmann::json json = nlohmann::json::array();
        for (const py::handle item : object) {
            json.push_back(toJson(item, what));
        }
        return json;
    }
    // numpy scalars and arrays: item() and tolist() give the plain Python values.
    if (py::isinstance<py::array>(object)) {
        return toJson(object.attr("tolist")(), what);
    }
    if (py::hasattr(object, "dtype") && py::hasattr(object, "item")) {
        return toJson(object.attr("item")(), what);
    }
    throw py::value_error(fmt::format("{}: a {} cannot be written as JSON", what,
                                      py::type::of(object).attr("__name__").cast<std::string>()));
}

}  // namespace subscan::python
