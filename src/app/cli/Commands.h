#pragma once

#include <functional>

#include <CLI/CLI.hpp>

namespace subscan::cli {

/// A subcommand as registered on the top-level app: its CLI11 node and what runs it once
/// parsed (returning the exit code). The options live in the closure.
struct Command {
    CLI::App* app = nullptr;
    std::function<int()> run;
};

Command addBenchCommand(CLI::App& parent);
Command addConvertCommand(CLI::App& parent);
Command addEvalCommand(CLI::App& parent);
Command addFitProfileCommand(CLI::App& parent);
Command addIndexCommand(CLI::App& parent);
Command addInfoCommand(CLI::App& parent);
Command addMaterialsCommand(CLI::App& parent);
Command addRenderCommand(CLI::App& parent);
Command addScanCommand(CLI::App& parent);
Command addTurntableCommand(CLI::App& parent);
Command addViewCommand(CLI::App& parent);

/// Parses the command line and runs the chosen subcommand. Exit codes: 0 success, 1 an error
/// with the input or the machine (one sentence on stderr), 2 bad command-line usage, 128 + the
/// signal for a command stopped by Ctrl-C (130) or SIGTERM (143).
int run(int argc, char** argv);

}  // namespace subscan::cli
