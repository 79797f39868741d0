// vitri: command-line entry point. `vitri COMMAND [ARGS...]`; `vitri --help` lists the commands.
#include "commands.hpp"
#include "vitri/core/error.hpp"

#include <cstdio>
#include <exception>
#include <iostream>
#include <string>

namespace vitri::cli {

// Each subcommand lives in its own cmd_*.cpp; declare it here and add it to the table below.
int run_render(const Args& args);  // cmd_render.cpp
const char* render_usage();
int run_tetrahedralize(const Args& args);  // cmd_tetrahedralize.cpp
const char* tetrahedralize_usage();
int run_eval(const Args& args);  // cmd_eval.cpp
const char* eval_usage();
int run_mesh(const Args& args);  // cmd_mesh.cpp
const char* mesh_usage();
#ifdef VITRI_HAVE_STUDIO
int run_studio(const Args& args);  // cmd_studio.cpp (built when cpp-httplib is found)
const char* studio_usage();
#endif
const std::vector<Command>& commands() {
  static const std::vector<Command> table = {
      {"eval", "fit the implicit function of an input and print f and its gradient at query points", eval_usage(),
       run_eval},
      {"mesh", "mesh the implicit surface of constraints, oriented points or a mesh at levels of detail; replay edits",
       mesh_usage(), run_mesh},
      {"render", "draw meshes to a PNG picture (software renderer)", render_usage(), run_render},
#ifdef VITRI_HAVE_STUDIO
      {"studio", "model a variational surface interactively in the browser (local web server)", studio_usage(),
       run_studio},
#endif
      {"tetrahedralize", "exact Delaunay tetrahedralization of a point file in a box", tetrahedralize_usage(),
       run_tetrahedralize},
  };
  return table;
}

}  // namespace vitri::cli

namespace {

void print_help() {
  std::cout << "vitri: dynamic triangulation of variational implicit surfaces\n\n"
               "usage: vitri COMMAND [ARGS...]\n       vitri COMMAND --help\n\ncommands:\n";
  for (const auto& c : vitri::cli::commands()) std::cout << "  " << c.name << "\t" << c.summary << "\n";
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2 || std::string(argv[1]) == "-h" || std::string(argv[1]) == "--help") {
    print_help();
    return argc < 2 ? 2 : 0;
  }
  const std::string name = argv[1];
  vitri::cli::Args args(argv + 2, argv + argc);
  for (const auto& c : vitri::cli::commands()) {
    if (name != c.name) continue;
    if (vitri::cli::wants_help(args)) {
      std::cout << c.usage;
      return 0;
    }
    try {
      return c.run(args);
    } catch (const vitri::Error& e) {
      std::cerr << "vitri " << name << ": error: " << e.what() << "\n";
      return 1;
    } catch (const std::exception& e) {
      std::cerr << "vitri " << name << ": internal error: " << e.what() << "\n";
      return 3;
    }
  }
  std::cerr << "vitri: unknown command '" << name << "' (try vitri --help)\n";
  return 2;
}
