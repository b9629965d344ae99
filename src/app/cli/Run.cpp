#include <cstdio>
#include <exception>
#include <new>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include <fmt/format.h>

#include "app/cli/Commands.h"
#include "app/cli/InterruptWatcher.h"
#include "core/Error.h"

namespace subscan::cli {

namespace {

constexpr int kExitError = 1;
constexpr int kExitUsage = 2;

/// Pages of the manual (docs/ in the source tree) beside each command's reference in
/// docs/cli.md; tests/docs checks that every page and anchor a --help names exists.
constexpr std::pair<std::string_view, std::string_view> kTopicPages[] = {
    {"render", "docs/pipeline.md"},
    {"turntable", "docs/temporal.md"},
    {"eval", "docs/eval.md"},
    {"bench", "bench/README.md"},
    {"materials", "docs/scattering.md"},
    {"fit-profile", "docs/scattering.md"},
    {"scan", "docs/surveys.md"},
    {"info", "docs/formats.md"},
    {"convert", "docs/formats.md"},
    {"index", "docs/surveys.md"},
};

/// Ends every command's --help with the manual's pages that cover it.
void addManualFooters(CLI::App& app) {
    app.footer("Manual: README.md and docs/ in the subscan sources (docs/cli.md: every command)");
    for (CLI::App* command : app.get_subcommands({})) {
        std::string footer = fmt::format("Manual: docs/cli.md#subscan-{}", command->get_name());
        for (const auto& [name, page] : kTopicPages) {
            if (name == command->get_name()) {
                footer += fmt::format(" and {}", page);
            }
        }
        command->footer(footer);
    }
}

}  // namespace

int run(int argc, char** argv) {
    CLI::App app{"subscan: real-time solid, lit and translucent rendering of raw 3D scans",
                 "subscan"};
    app.require_subcommand(1);
    app.set_version_flag("--version", "subscan 0.1.0");

    const std::vector<Command> commands{
        addInfoCommand(app),      addRenderCommand(app),     addScanCommand(app),
        addConvertCommand(app),   addEvalCommand(app),       addBenchCommand(app),
        addMaterialsCommand(app), addFitProfileCommand(app), addViewCommand(app),
        addTurntableCommand(app), addIndexCommand(app)};
    addManualFooters(app);

    try {
        app.parse(argc, argv);
    } catch (const CLI::ParseError& error) {
        const int code = app.exit(error);
        return code == static_cast<int>(CLI::ExitCodes::Success) ? 0 : kExitUsage;
    }

    try {
        for (const Command& command : commands) {
            if (command.app->parsed()) {
                return command.run();
            }
        }
    } catch (const Interrupted& interrupted) {
        fmt::print(stderr, "subscan: {}\n", interrupted.what());
        return interrupted.exitStatus();
    } catch (const Error& error) {
        fmt::print(stderr, "subscan: {}\n", error.what());
        return kExitError;
    } catch (const std::bad_alloc&) {
        fmt::print(stderr,
                   "subscan: out of memory (the scan or the requested image is too large "
                   "for this machine)\n");
        return kExitError;
    } catch (const std::exception& error) {
        fmt::print(stderr, "subscan: internal error: {}\n", error.what());
        return kExitError;
    }
    return kExitUsage;
}

}  // namespace subscan::cli
