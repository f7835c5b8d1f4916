// wiretool subcommands: each file registers one subcommand on the CLI11 app and runs it.
#pragma once

#include <CLI/CLI.hpp>

#include <functional>
#include <optional>
#include <string>
#include <utility>

namespace wiretool {

/// Exit statuses shared by every subcommand (a contract: scripts test them).
enum Exit : int {
    exit_ok = 0,
    exit_failure = 1,    ///< the tool could not finish (an output could not be written, an internal error)
    exit_bad_input = 2,  ///< the input or the command line is wrong; nothing was written
};

/// "WxH" with whole numbers in [1, 16384] (--size of view and bench); nothing when it is not that.
std::optional<std::pair<int, int>> parse_size_wxh(const std::string& text);

/// A subcommand registers its options and returns the action to run when it was chosen.
using Action = std::function<int()>;

Action add_mesh_command(CLI::App& app);
Action add_bend_command(CLI::App& app);
Action add_bench_command(CLI::App& app);
Action add_view_command(CLI::App& app);

}  // namespace wiretool
