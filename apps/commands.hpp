#pragma once
// The subcommands of the vitri CLI. Each takes the arguments after its name and returns the exit code.
// A command throws vitri::Error (or std::exception) on bad input; main() prints it and returns 1.

#include "vitri/rbf/constraints.hpp"

#include <string>
#include <vector>

namespace vitri::cli {

using Args = std::vector<std::string>;

/// One subcommand: its name, a one-line summary, its usage text and its entry point.
struct Command {
  const char* name;
  const char* summary;
  const char* usage;
  int (*run)(const Args& args);
};

/// All subcommands, in the order `vitri --help` lists them (defined in main.cpp).
const std::vector<Command>& commands();

/// True when args holds -h or --help.
bool wants_help(const Args& args);

/// Ends the process with `code` once stdout and stderr are flushed, without running destructors: for a
/// command whose output is complete (files closed) and whose structures are large, so that the process
/// does not spend its last half second freeing millions of blocks one by one (a 10^6-point `vitri mesh`:
/// 0.5 s) when the system reclaims its memory at once. Call it only where nothing else remains to write.
[[noreturn]] void exit_without_teardown(int code);

}  // namespace vitri::cli
