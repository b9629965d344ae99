#include <cstdio>
#include <exception>
#include <new>
#include <vector>

#include <fmt/format.h>

#include "app/cli/Commands.h"
#include "core/Error.h"

namespace subscan::cli {

namespace {

constexpr int kExitError = 1;
constexpr int kExitUsage = 2;

}  // namespace

int run(int argc, char** argv) {
    CLI::App app{"subscan: real-time solid, lit and translucent rendering of raw 3D scans",
                 "subscan"};
    app.require_subcommand(1);
    app.set_version_flag("--version", "subscan 0.1.0");

    const std::vector<Command> commands{addInfoCommand(app),      addRenderCommand(app),
                                        addScanCommand(app),      addConvertCommand(app),
                                        addEvalCommand(app),      addBenchCommand(app),
                                        addMaterialsCommand(app), addFitProfileCommand(app),
                                        addViewCommand(app),      addTurntableCommand(app)};

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
