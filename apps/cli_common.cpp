#include "commands.hpp"

#include <algorithm>
#include <cstdio>
#include <cstdlib>

namespace vitri::cli {

bool wants_help(const Args& args) {
  return std::any_of(args.begin(), args.end(), [](const std::string& a) { return a == "-h" || a == "--help"; });
}

void exit_without_teardown(int code) {
  std::fflush(stdout);
  std::fflush(stderr);
  std::_Exit(code);
}

}  // namespace vitri::cli
