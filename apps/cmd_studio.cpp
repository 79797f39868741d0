// `vitri studio`: the interactive modeler in the browser (apps/studio/, docs/studio.md).
#include "commands.hpp"
#include "input.hpp"
#include "studio/server.hpp"

#include "vitri/core/error.hpp"

#include <pthread.h>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <thread>

#ifndef VITRI_STUDIO_WEB_DIR
#error "VITRI_STUDIO_WEB_DIR must name the folder of the studio's page"
#endif
#ifndef VITRI_THREE_DIR
#error "VITRI_THREE_DIR must name the three.js installation"
#endif

namespace vitri::cli {
namespace {

const char* const kUsage =
    "usage: vitri studio [INPUT] [--port N] [--host ADDR] [--precision P] [--function F]\n"
    "                    [--offset D] [--sides both|inside|outside] [--neighbours K]\n"
    "                    [--viewpoint X Y Z] [--drag-levels K] [--certify [--certify-floor F]]\n"
    "                    [--no-socket]\n"
    "\n"
    "Starts the interactive modeler: a local web server; open the printed address in a browser. Click\n"
    "the surface to add a constraint, shift+click / alt+click for an outside / inside one, drag a\n"
    "constraint to move it; undo, redo, delete, change a value, precision slider, open a file, save the\n"
    "constraints (.xyzv), export the mesh (OBJ, PLY, OFF, STL). The page and its HTTP/JSON API:\n"
    "docs/studio.md.\n"
    "\n"
    "INPUT             any input of vitri mesh (.xyzv, .xyz, .pwn, .pcd, .off, .obj, .ply, .stl); points\n"
    "                  (with or without normals) are read as vitri mesh reads a scan (docs/scans.md:\n"
    "                  outliers set aside, normals oriented without refusing; the report on stderr);\n"
    "                  without it, a blob of 25 constraints\n"
    "  --port N        TCP port (default 8080; 0: any free port)\n"
    "  --host ADDR     address to bind (default 127.0.0.1, this machine only; 0.0.0.0 exposes the\n"
    "                  studio and its edits to the network)\n"
    "  --precision P   target relative precision (default 0.02); the mesh starts 4x coarser and is\n"
    "                  refined while the page is idle\n"
    "  --function F    implicit function: global (the RBF of the paper), local (partition of unity:\n"
    "                  local edits, 10^5+ constraints) or auto (default: global up to 4000\n"
    "                  constraints, local above; docs/local_rbf.md)\n"
    "  --drag-levels K with the global function, edits are shown first on a preview K halvings\n"
    "                  coarser than the target (default 1; 0: every edit at the target) above\n"
    "                  5000 triangles; the target mesh follows in the next idle step\n"
    "  --offset D, --sides S   as vitri mesh, for points and meshes\n"
    "  --neighbours K  as vitri mesh: neighbours per point of a scan (default: from the data)\n"
    "  --viewpoint X Y Z  as vitri mesh: the sensor's position for INPUT's points (default: the\n"
    "                  input's: PCD VIEWPOINT, NAME.viewpoint beside it)\n"
    "  --certify       certified levels, as vitri mesh --certify (docs/certificate.md): every refinement\n"
    "                  checks what changed and refines what it cannot certify; the status line says\n"
    "                  'certified' or how many tetrahedra are not (slower: global-function edits check\n"
    "                  the whole domain)\n"
    "  --certify-floor F  the size floor of --certify, a fraction of the precision (default 0.1)\n"
    "  --no-socket     HTTP only: no WebSocket beside it (by default the page sends its requests\n"
    "                  over a WebSocket on a second, free port of the same host: faster updates)\n"
    "\n"
    "Stops on Ctrl-C. Exit status: 0 stopped, 1 bad input, 2 usage error.\n";

int usage_error(const std::string& what) {
  std::cerr << "vitri studio: " << what << "\n(try vitri studio --help)\n";
  return 2;
}

bool parse_number(const std::string& s, double& out) {
  char* e = nullptr;
  out = std::strtod(s.c_str(), &e);
  return !s.empty() && *e == '\0' && std::isfinite(out);
}

/// The default model: 24 on-surface points on a lumpy sphere around one inside constraint.
Constraints default_blob() {
  Constraints c;
  c.add({0, 0, 0}, -1.0);
  for (int i = 0; i < 24; ++i) {
    const double z = 1 - (2 * i + 1) / 24.0, r = std::sqrt(1 - z * z), a = 2.399963 * i;
    const double s = 1 + 0.15 * std::sin(3 * a) * r;
    c.add({s * r * std::cos(a), s * r * std::sin(a), 0.8 * s * z}, 0.0);
  }
  return c;
}

struct StudioArgs {
  std::string input;
  ScanOptions scan;              // --neighbours; --viewpoint for INPUT only
  bool viewpoint_given = false;
  studio::SessionOptions session;
  studio::ServerOptions server;
};

/// Parses the arguments into `out`; returns an empty string or the usage error.
std::string parse_args(const Args& args, StudioArgs& out) {
  out.session.mesher.function = FunctionKind::Auto;  // as vitri mesh
  out.session.mesher.constraint_build.offset_spacings = kOffsetSpacings;
  for (std::size_t i = 0; i < args.size(); ++i) {
    const std::string& a = args[i];
    const bool has_value = i + 1 < args.size();
    const std::string v = has_value ? args[i + 1] : std::string();
    double d = 0;
    if (a == "--port" || a == "--host" || a == "--precision" || a == "--function" || a == "--offset" ||
        a == "--sides" || a == "--drag-levels" || a == "--neighbours" || a == "--certify-floor") {
      if (!has_value) return a + " needs a value";
      ++i;
    }
    if (a == "--port") {
      if (!parse_number(v, d) || d < 0 || d > 65535 || d != std::floor(d)) return "--port needs 0..65535";
      out.server.port = static_cast<int>(d);
    } else if (a == "--host") {
      out.server.host = v;
    } else if (a == "--precision") {
      if (!parse_number(v, d) || !(d > 0) || d > 1) return "--precision needs a number in (0, 1], got " + v;
      out.session.precision = d;
    } else if (a == "--drag-levels") {
      if (!parse_number(v, d) || d < 0 || d > 8 || d != std::floor(d)) return "--drag-levels needs 0..8, got " + v;
      out.session.drag_levels = static_cast<int>(d);
    } else if (a == "--function") {
      if (v == "global") out.session.mesher.function = FunctionKind::Global;
      else if (v == "local") out.session.mesher.function = FunctionKind::Local;
      else if (v == "auto") out.session.mesher.function = FunctionKind::Auto;
      else return "--function must be global, local or auto, got '" + v + "'";
    } else if (a == "--offset") {
      if (!parse_number(v, d) || !(d > 0)) return "--offset needs a positive number";
      out.session.mesher.constraint_build.offset = d;
      out.session.mesher.constraint_build.offset_spacings = 0.0;
    } else if (a == "--sides") {
      if (v == "both")
        out.session.mesher.constraint_build.sides = OffSurface::Both;
      else if (v == "inside")
        out.session.mesher.constraint_build.sides = OffSurface::Inside;
      else if (v == "outside")
        out.session.mesher.constraint_build.sides = OffSurface::Outside;
      else
        return "--sides must be both, inside or outside, got '" + v + "'";
    } else if (a == "--neighbours") {
      if (!parse_number(v, d) || d < 0 || d > 1e6 || d != std::floor(d)) return "--neighbours needs a count, got " + v;
      out.scan.k = static_cast<std::size_t>(d);
    } else if (a == "--viewpoint") {
      double xyz[3];
      for (double& x : xyz) {
        if (i + 1 >= args.size() || !parse_number(args[i + 1], x)) return "--viewpoint needs three finite numbers X Y Z";
        ++i;
      }
      out.scan.viewpoint = Point3{xyz[0], xyz[1], xyz[2]};
      out.viewpoint_given = true;
    } else if (a == "--certify") {
      out.session.mesher.polygonizer.certify = true;
    } else if (a == "--certify-floor") {
      if (!parse_number(v, d) || !(d > 0) || d > 1) return "--certify-floor needs a fraction of the precision in (0, 1]";
      out.session.mesher.polygonizer.certify_floor_fraction = d;
    } else if (a == "--no-socket") {
      out.server.socket = false;
    } else if (!a.empty() && a[0] == '-') {
      return "unknown option '" + a + "'";
    } else if (out.input.empty()) {
      out.input = a;
    } else {
      return "more than one input ('" + out.input + "', '" + a + "')";
    }
  }
  return {};
}

}  // namespace

const char* studio_usage() {
  return kUsage;
}

int run_studio(const Args& args) {
  StudioArgs sa;
  sa.server.web_dir = VITRI_STUDIO_WEB_DIR;
  sa.server.three_dir = VITRI_THREE_DIR;
  if (const char* web = std::getenv("VITRI_STUDIO_WEB_DIR")) sa.server.web_dir = web;
  const std::string bad = parse_args(args, sa);
  if (!bad.empty()) return usage_error(bad);
  const ConstraintBuildOptions& build = sa.session.mesher.constraint_build;
  Constraints constraints;
  if (sa.input.empty()) {
    constraints = default_blob();
  } else {
    Input in = read_input(sa.input);
    repair_mesh(in, sa.input, "vitri studio");  // as vitri mesh: no-area triangles, a soup's vertices
    const bool points = is_scan(in);
    ScanFit fit;
    constraints = constraints_of(std::move(in), sa.input, build, nullptr, sa.scan, &fit);
    if (points) std::fprintf(stderr, "%s\n", describe_scan(fit, sa.viewpoint_given).c_str());
  }
  std::fprintf(stderr, "fitting %zu constraints...\n", constraints.size());
  studio::Session session(std::move(constraints), sa.input.empty() ? "blob" : sa.input, sa.session);
  ScanOptions upload_scan = sa.scan;  // uploads: the file's viewpoint or the request's
  upload_scan.viewpoint.reset();
  studio::Api api(session, build, upload_scan);
  studio::Server server(api, sa.server);
  // Ctrl-C / SIGTERM: a thread waits for them and stops the server (no work inside a signal handler).
  sigset_t stop_signals;
  sigemptyset(&stop_signals);
  sigaddset(&stop_signals, SIGINT);
  sigaddset(&stop_signals, SIGTERM);
  pthread_sigmask(SIG_BLOCK, &stop_signals, nullptr);
  const int port = server.bind();
  std::printf("vitri studio: %s, %zu constraints; open http://%s:%d/  (Ctrl-C stops)\n",
              session.name().c_str(), session.size(),
              sa.server.host == "0.0.0.0" ? "127.0.0.1" : sa.server.host.c_str(), port);
  std::fflush(stdout);
  std::thread waiter([&] {
    int sig = 0;
    sigwait(&stop_signals, &sig);
    server.stop();
  });
  server.run();
  pthread_kill(waiter.native_handle(), SIGTERM);  // wakes the waiter when run() ended on its own
  waiter.join();
  return 0;
}

}  // namespace vitri::cli
