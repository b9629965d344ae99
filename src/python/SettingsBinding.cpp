// subscan.Settings: the settings file of `subscan render --settings`, with attribute access.
#include <string>

#include <fmt/format.h>
#include <pybind11/stl.h>
#include <nlohmann/json.hpp>

#include "core/Error.h"
#include "io/JsonText.h"
#include "python/Bindings.h"
#include "python/JsonConversion.h"

namespace py = pybind11;

namespace subscan::python {

namespace {

constexpr const char* kSections[] = {"raster",     "surface",  "shading",
                                     "scattering", "temporal", "streaming"};

/// `settings` with the settings-file JSON `patch` written over it (absent keys keep their
/// values); ValueError with the library's sentence for unknown keys and bad values.
RenderSettings patched(const RenderSettings& settings, const nlohmann::json& patch) {
    RenderSettings result = settings;
    try {
        patch.get_to(result);
    } catch (const Error& error) {
        throw py::value_error(error.what());
    }
    return result;
}

nlohmann::json parseJson(const py::handle& object, std::string_view what) {
    if (py::isinstance<py::str>(object)) {
        try {
            return parseJsonText(object.cast<std::string>());
        } catch (const Error& error) {
            throw py::value_error(error.what());
        }
    }
    return toJson(object, what);
}

/// One section of a Settings (settings.raster, ...): reads and writes its keys in place.
struct SettingsSection {
    SettingsHandle settings;
    std::string name;

    nlohmann::json json() const { return nlohmann::json(settings->value).at(name); }

    /// AttributeError with the library's sentence (the one a settings file with this key gets)
    /// unless the section has `key`.
    void requireKey(const std::string& key) const {
        if (json().contains(key)) {
            return;
        }
        std::string message = fmt::format("unknown setting '{}' in '{}'", key, name);
        try {
            patched(settings->value, {{name, {{key, nullptr}}}});
        } catch (const py::value_error& error) {
            message = error.what();
        }
        throw py::attribute_error(message);
    }
    py::object get(const std::string& key) const {
        requireKey(key);
        return toPython(json().at(key));
    }
    void set(const std::string& key, const py::handle& value) {
        requireKey(key);
        const nlohmann::json patch = {{name, {{key, toJson(value, key)}}}};
        settings->value = patched(settings->value, patch);
    }
};

SettingsHandle settingsFromPythonJson(const py::handle& object) {
    return std::make_shared<SettingsData>(
        SettingsData{patched(RenderSettings{}, parseJson(object, "the settings"))});
}

std::string dumped(const RenderSettings& settings) {
    return nlohmann::json(settings).dump(2) + "\n";
}

}  // namespace

RenderSettings settingsArgument(const py::handle& argument) {
    if (argument.is_none()) {
        return {};
    }
    if (py::isinstance<SettingsData>(argument)) {
        return argument.cast<const SettingsData&>().value;
    }
    if (py::isinstance<py::dict>(argument)) {
        return patched(RenderSettings{}, toJson(argument, "the settings"));
    }
    throw py::type_error(fmt::format("settings must be a subscan.Settings, a dict or None, not {}",
                                     py::type::of(argument).attr("__name__").cast<std::string>()));
}

void bindSettings(py::module_& module) {
    py::class_<SettingsSection>(module, "SettingsSection", R"doc(
One section of a Settings (settings.raster, .surface, .shading, .scattering, .temporal,
.streaming): its
keys are attributes, read as plain Python values and written with the settings file's checks.
A key the section lacks raises AttributeError; a bad value raises ValueError.
)doc")
        .def("__getattr__", &SettingsSection::get)
        .def("__setattr__", &SettingsSection::set)
        .def("__dir__",
             [](const SettingsSection& self) {
                 py::list keys;
                 const nlohmann::json section = self.json();  // items() does not own it
                 for (const auto& [key, value] : section.items()) {
                     keys.append(key);
                 }
                 return keys;
             })
        .def(
            "to_dict", [](const SettingsSection& self) { return toPython(self.json()); },
            "The section as a dict (a copy).")
        .def("__repr__", [](const SettingsSection& self) {
            return fmt::format("<subscan.Settings.{} {}>", self.name, self.json().dump());
        });

    py::class_<SettingsData, SettingsHandle>(module, "Settings", R"doc(
Every pipeline setting, as `subscan render --settings FILE` reads it and --save-settings writes
it: sections raster, surface, shading, scattering, temporal and streaming, each a set of keys
(streaming: how `render` and the viewer read COPC and EPT surveys; a Renderer loads whole).

    s = subscan.Settings(raster={"mode": "sss"}, scattering={"material": "skin1"})
    s.surface.visibility_threshold = 0.2
    s.raster.mdoe = "surface"          # AttributeError: unknown setting 'mdoe' in 'raster' ...
    s.shading.specular = 7             # ValueError: the setting 'specular' = 7 is outside 0..1
    s.save("settings.json"); subscan.Settings.load("settings.json")

Settings(**sections) starts from the defaults and writes the given sections' keys over them.
)doc")
        .def(py::init([](const py::kwargs& sections) { return settingsFromPythonJson(sections); }))
        .def_static(
            "load",
            [](const py::object& path) {
                return std::make_shared<SettingsData>(
                    SettingsData{readSettingsFile(pathArgument(path))});
            },
            py::arg("path"),
            "Reads a settings file; absent keys keep the defaults (subscan.Error names the file "
            "and the bad setting).")
        .def(
            "save",
            [](const SettingsData& self, const py::object& path) {
                writeSettingsFile(pathArgument(path), self.value);
            },
            py::arg("path"), "Writes the settings file (all keys), atomically.")
        .def_static("from_json", &settingsFromPythonJson, py::arg("json"),
                    "Settings from the settings file's text (str) or its dict, over the "
                    "defaults; ValueError names an unknown key or a bad value.")
        .def(
            "to_json", [](const SettingsData& self) { return dumped(self.value); },
            "The settings file's text, every key.")
        .def(
            "to_dict",
            [](const SettingsData& self) { return toPython(nlohmann::json(self.value)); },
            "The settings as nested dicts (a copy).")
        .def(
            "update",
            [](SettingsData& self, const py::dict& sections) {
                self.value = patched(self.value, toJson(sections, "the settings"));
            },
            py::arg("sections"),
            "Writes the keys of a dict in the settings file's layout over these settings.")
        .def(
            "copy", [](const SettingsData& self) { return std::make_shared<SettingsData>(self); },
            "An independent copy.")
        .def("__copy__",
             [](const SettingsData& self) { return std::make_shared<SettingsData>(self); })
        .def(
            "__deepcopy__",
            [](const SettingsData& self, const py::object&) {
                return std::make_shared<SettingsData>(self);
            },
            py::arg("memo"))
        .def(
            "__eq__",
            [](const SettingsData& self, const SettingsData& other) {
                return self.value == other.value;
            },
            py::is_operator())
        .def("__getattr__",
             [](const SettingsHandle& self, const std::string& name) {
                 for (const char* section : kSections) {
                     if (name == section) {
                         return SettingsSection{self, name};
                     }
                 }
                 std::string message = fmt::format("unknown settings section '{}'", name);
                 try {
                     patched(self->value, {{name, nlohmann::json::object()}});
                 } catch (const py::value_error& error) {
                     message = error.what();
                 }
                 throw py::attribute_error(message);
             })
        .def("__setattr__",
             [](const SettingsHandle&, const std::string& name, const py::object&) {
                 throw py::attribute_error(fmt::format(
                     "cannot replace '{}': set its keys (settings.raster.mode = 'surface') or "
                     "call settings.update({{'{}': {{...}}}})",
                     name, name));
             })
        .def("__dir__",
             [](const py::object& self) {
                 py::list names;
                 for (const char* section : kSections) {
                     names.append(section);
                 }
                 for (const char* method :
                      {"load", "save", "from_json", "to_json", "to_dict", "update", "copy"}) {
                     names.append(method);
                 }
                 (void)self;
                 return names;
             })
        .def("__repr__", [](const SettingsData& self) {
            return fmt::format("<subscan.Settings {}>", nlohmann::json(self.value).dump());
        });
}

}  // namespace subscan::python
