#include "commands.hpp"

#include <algorithm>

namespace vitri::cli {

bool wants_help(const Args& args) {
  return std::any_of(args.begin(), args.end(), [](const std::string& a) { return a == "-h" || a == "--help"; });
}

}  // namespace vitri::cli
