// The studio's HTTP/JSON API: parsing and validating requests, calling the session, writing JSON.
#include "api.hpp"

#include "input.hpp"
#include "mesh_view.hpp"
#include "json.hpp"

#include "vitri/core/error.hpp"
#include "vitri/io/io.hpp"

#include <unistd.h>
#include <cctype>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <limits>
#include <sstream>

namespace vitri::studio {
namespace {

/// A bad request: answered with 400 and the message.
class BadRequest : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

ApiResponse json_response(std::string body) {
  ApiResponse r;
  r.body = std::move(body);
  return r;
}

Json parse_body(const std::string& body) {
  if (body.empty()) return Json(Json::Object{});
  Json j = Json::parse(body);
  j.as_object("the request body");
  return j;
}

/// Rejects keys other than `allowed` (a typo must not be silently ignored).
void check_keys(const Json& o, std::initializer_list<const char*> allowed) {
  for (const auto& [key, value] : o.as_object("the request body")) {
    bool ok = false;
    for (const char* a : allowed) ok = ok || key == a;
    if (!ok) throw BadRequest("unknown key \"" + key + "\"");
  }
}

const Json& member(const Json& o, const char* key) {
  const Json* v = o.find(key);
  if (!v) throw BadRequest(std::string("missing \"") + key + "\"");
  return *v;
}

double finite_number(const Json& o, const char* key) {
  const double d = member(o, key).as_number(std::string("\"") + key + "\"");
  if (!std::isfinite(d)) throw BadRequest(std::string("\"") + key + "\" must be finite");
  return d;
}

std::size_t index_member(const Json& o, const char* key) {
  const double d = finite_number(o, key);
  if (d < 0 || d != std::floor(d) || d > 9007199254740992.0)
    throw BadRequest(std::string("\"") + key + "\" must be a non-negative integer");
  return static_cast<std::size_t>(d);
}

Point3 point_member(const Json& o, const char* key) {
  const Json::Array& a = member(o, key).as_array(std::string("\"") + key + "\"");
  if (a.size() != 3) throw BadRequest(std::string("\"") + key + "\" must hold 3 numbers");
  Point3 p;
  for (std::size_t k = 0; k < 3; ++k) {
    p[k] = a[k].as_number(std::string("\"") + key + "\"[" + std::to_string(k) + "]");
    if (!std::isfinite(p[k])) throw BadRequest(std::string("\"") + key + "\" must be finite");
  }
  return p;
}

bool bool_member(const Json& o, const char* key, bool fallback) {
  const Json* v = o.find(key);
  return v ? v->as_bool(std::string("\"") + key + "\"") : fallback;
}

std::string param(const ApiRequest& r, const std::string& key, const std::string& fallback = {}) {
  const auto it = r.params.find(key);
  return it == r.params.end() ? fallback : it->second;
}

/// The version a client holds (query parameter `key`, default "since"; absent: 0 = none), at most `max`.
std::uint64_t version_param(const ApiRequest& r, std::uint64_t max, const char* key = "since") {
  const std::string s = param(r, key, "0");
  char* end = nullptr;
  errno = 0;
  const unsigned long long v = std::strtoull(s.c_str(), &end, 10);
  if (s.empty() || *end != '\0' || s[0] == '-' || errno == ERANGE || v > max)
    throw BadRequest("\"" + std::string(key) + "\" must be a version (a non-negative integer), got '" + s + "'");
  return v;
}

bool exact_param(const ApiRequest& r) {
  const std::string exact = param(r, "exact", "1");
  if (exact != "0" && exact != "1") throw BadRequest("\"exact\" must be 0 or 1, got '" + exact + "'");
  return exact == "1";
}

/// Query parameters "mesh" and "exact" of an edit, undo or redo; read before the edit, so that a bad one
/// changes nothing.
MeshWanted mesh_wanted(const ApiRequest& r) {
  MeshWanted m;
  if (r.params.find("mesh") == r.params.end()) return m;
  m.wanted = true;
  m.since = static_cast<std::uint32_t>(version_param(r, 0xffffffffull, "mesh"));
  m.exact = exact_param(r);
  return m;
}

std::string constraint_json(const ConstraintInfo& c) {
  return "{\"index\":" + std::to_string(c.index) + ",\"id\":" + std::to_string(c.id) + ",\"position\":[" +
         json_number(c.position.x) + "," + json_number(c.position.y) + "," + json_number(c.position.z) +
         "],\"value\":" + json_number(c.value) + "}";
}

/// {"base","version","full","changes":[{"op":"add"|"remove"|"update", <constraint>}..]} (docs/studio.md).
std::string constraint_delta_json(const ConstraintDelta& d) {
  std::string out = "{\"base\":" + std::to_string(d.base) + ",\"version\":" + std::to_string(d.version) +
                    ",\"full\":" + (d.full ? "true" : "false") + ",\"changes\":[";
  for (std::size_t k = 0; k < d.changes.size(); ++k) {
    const ConstraintChange& c = d.changes[k];
    const char* op = c.op == ConstraintChange::Op::Add      ? "add"
                     : c.op == ConstraintChange::Op::Remove ? "remove"
                                                            : "update";
    if (k) out.push_back(',');
    out += "{\"op\":\"" + std::string(op) + "\"," + constraint_json(c.constraint).substr(1);
  }
  return out + "]}";
}

std::string points_json(const std::vector<Point3>& pts) {
  std::string out = "[";
  for (std::size_t i = 0; i < pts.size(); ++i) {
    if (i) out.push_back(',');
    out += "[" + json_number(pts[i].x) + "," + json_number(pts[i].y) + "," + json_number(pts[i].z) + "]";
  }
  return out + "]";
}

/// The current mesh as {"vertices": [[x,y,z]..], "triangles": [[a,b,c]..]} (for scripts and tests).
std::string indexed_mesh_json(const SurfaceMesh& m) {
  std::string out = "{\"vertices\":" + points_json(m.vertices) + ",\"triangles\":[";
  for (std::size_t t = 0; t < m.triangles.size(); ++t) {
    if (t) out.push_back(',');
    const auto& f = m.triangles[t];
    out += "[" + std::to_string(f[0]) + "," + std::to_string(f[1]) + "," + std::to_string(f[2]) + "]";
  }
  return out + "]}";
}

std::string read_whole_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

/// A download name: the session name's stem (letters, digits, '-', '_' kept) and the extension.
std::string download_name(const std::string& name, const std::string& ext) {
  std::string stem = name.substr(0, name.find_last_of('.'));
  const std::size_t slash = stem.find_last_of("/\\");
  if (slash != std::string::npos) stem = stem.substr(slash + 1);
  std::string clean;
  for (const char c : stem)
    if (std::isalnum(static_cast<unsigned char>(c)) || c == '-' || c == '_') clean.push_back(c);
  return (clean.empty() ? "model" : clean) + "." + ext;
}

}  // namespace

ApiResponse error_response(int status, const std::string& what) {
  ApiResponse r;
  r.status = status;
  r.body = "{\"error\":" + json_quote(what) + "}";
  return r;
}

Api::Api(Session& session, const ConstraintBuildOptions& build, const ScanOptions& scan)
    : session_(session), build_(build), scan_(scan) {
  const char* tmp = std::getenv("TMPDIR");
  std::string pattern = std::string(tmp && *tmp ? tmp : "/tmp") + "/vitri-studio-XXXXXX";
  if (!mkdtemp(pattern.data())) throw Error("studio: cannot create a private temporary directory");
  temp_dir_ = pattern;
}

Api::~Api() {
  for (const char* ext : {"xyzv", "obj", "ply", "off", "stl"}) std::remove(temp_path(ext).c_str());
  rmdir(temp_dir_.c_str());
}

std::string Api::temp_path(const std::string& ext) const {
  return temp_dir_ + "/export." + ext;
}

bool Api::is_api_path(const std::string& path) {
  return path.rfind("/api/", 0) == 0;
}

ApiResponse Api::handle(const ApiRequest& request) {
  try {
    std::unique_lock<std::mutex> lock(mutex_, std::defer_lock);
    if (request.path == "/api/refine") {  // yields to waiting requests, so it does not count as one
      lock.lock();
    } else {
      ++waiting_;
      lock.lock();
      --waiting_;
    }
    const auto t0 = std::chrono::steady_clock::now();
    ApiResponse out = route(request);
    out.server_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    return out;
  } catch (const BadRequest& e) {
    return error_response(400, e.what());
  } catch (const JsonError& e) {
    return error_response(400, e.what());
  } catch (const LimitError& e) {
    return error_response(413, e.what());
  } catch (const Error& e) {
    return error_response(400, e.what());
  } catch (const std::exception& e) {
    return error_response(500, std::string("internal error: ") + e.what());
  }
}

ApiResponse Api::route(const ApiRequest& r) {
  const std::string& p = r.path;
  const char* method =
      p == "/api/stats" || p == "/api/state" || p == "/api/constraints" || p == "/api/mesh" ||
              p == "/api/export"
          ? "GET"
      : p == "/api/edit" || p == "/api/undo" || p == "/api/redo" || p == "/api/refine" || p == "/api/load"
          ? "POST"
          : nullptr;
  if (!method) return error_response(404, "no such endpoint: " + p);
  if (r.method != method) return error_response(405, p + " takes " + method + ", not " + r.method);
  if (p == "/api/stats") return stats();
  if (p == "/api/state") return state();
  if (p == "/api/constraints")
    return json_response(constraint_delta_json(
        session_.constraint_delta(version_param(r, std::numeric_limits<std::uint64_t>::max()))));
  if (p == "/api/mesh") return mesh(r);
  if (p == "/api/export") return export_file(r);
  if (p == "/api/edit") return edit(r);
  if (p == "/api/refine") return refine(r);
  if (p == "/api/load") return load(r);
  check_keys(parse_body(r.body), {});
  const MeshWanted mesh = mesh_wanted(r);
  const std::uint64_t base = session_.constraint_version();
  const bool done = p == "/api/undo" ? session_.undo() : session_.redo();
  return with_mesh(mesh, stats_json(std::string("\"done\":") + (done ? "true" : "false") + changes_since(base)));
}

// An edit's JSON, and with "mesh=V" the mesh delta from version V in the same body (one round trip
// instead of two): a little-endian uint32 L, L bytes of JSON (padded with spaces to a multiple of 4, so
// that the delta's arrays stay aligned), then the delta as GET /api/mesh sends it (docs/studio.md).
ApiResponse Api::with_mesh(const MeshWanted& mesh, std::string json) {
  if (!mesh.wanted) return json_response(std::move(json));
  while (json.size() % 4) json.push_back(' ');
  const std::string delta = encode_binary(session_.delta(mesh.since, mesh.exact));
  ApiResponse out;
  out.content_type = "application/octet-stream";
  const auto n = static_cast<std::uint32_t>(json.size());
  out.body.reserve(4 + json.size() + delta.size());
  for (int k = 0; k < 4; ++k) out.body.push_back(static_cast<char>((n >> (8 * k)) & 0xffu));
  out.body += json;
  out.body += delta;
  return out;
}

std::string Api::stats_json(const std::string& extra) {
  session_.mesher().sync_surface();  // counts from the live mesh: no copy of the mesh per request
  const LiveMesh& m = session_.mesher().live_surface();
  const MesherStats s = session_.mesher().stats();
  const double current = session_.current_precision();
  std::string out = "{";
  if (!extra.empty()) out += extra + ",";
  out += "\"name\":" + json_quote(session_.name()) + ",\"constraints\":" + std::to_string(session_.size()) +
         ",\"vertices\":" + std::to_string(m.num_vertices()) +
         ",\"triangles\":" + std::to_string(m.num_triangles()) +
         ",\"precision\":" + (std::isfinite(current) ? json_number(current) : std::string("null")) +
         ",\"target_precision\":" + json_number(session_.target_precision()) +
         ",\"refined\":" + (session_.refined() ? "true" : "false") +
         ",\"preview\":" + (session_.showing_preview() ? "true" : "false") +
         ",\"unit\":" + json_number(session_.unit()) +
         ",\"edit_ms\":" + json_number(session_.last_update().edit_ms) +
         ",\"rbf_ms\":" + json_number(s.edit_rbf_seconds * 1e3) +
         ",\"extract_ms\":" + json_number(session_.last_update().extract_ms) +
         ",\"delaunay_vertices\":" + std::to_string(s.polygonizer.vertices) +
         // The certified mode (docs/certificate.md): tetrahedra the last refinement left uncertified.
         ",\"certify\":" + (session_.mesher().options().polygonizer.certify ? "true" : "false") +
         ",\"uncertified\":" + std::to_string(s.polygonizer.uncertified) +
         ",\"certify_budget_reached\":" + (s.polygonizer.certify_budget_reached ? "true" : "false") +
         ",\"rebuilds\":" + std::to_string(s.rebuilds) +
         ",\"undo\":" + std::to_string(session_.undo_depth()) +
         ",\"redo\":" + std::to_string(session_.redo_depth()) +
         ",\"revision\":" + std::to_string(session_.revision()) +
         ",\"constraint_version\":" + std::to_string(session_.constraint_version()) +
         ",\"socket_port\":" + (socket_port_ > 0 ? std::to_string(socket_port_) : std::string("null")) + "}";
  return out;
}

std::string Api::changes_since(std::uint64_t base) const {
  return ",\"constraint_delta\":" + constraint_delta_json(session_.constraint_delta(base));
}

ApiResponse Api::stats() {
  return json_response(stats_json());
}

ApiResponse Api::state() {
  std::string list = "[";
  for (const ConstraintInfo& c : session_.constraints()) {
    if (list.size() > 1) list.push_back(',');
    list += constraint_json(c);
  }
  return json_response(stats_json("\"constraint_list\":" + list + "]"));
}

ApiResponse Api::mesh(const ApiRequest& r) {
  const std::string format = param(r, "format", "binary");
  if (format == "indexed") return json_response(indexed_mesh_json(session_.surface()));
  if (format != "binary" && format != "json")
    throw BadRequest("\"format\" must be binary, json or indexed, got '" + format + "'");
  const bool exact = exact_param(r);
  const auto since = static_cast<std::uint32_t>(version_param(r, 0xffffffffull));
  const ClientDelta d = session_.delta(since, exact);
  if (format == "json") return json_response(encode_json(d));
  ApiResponse out;
  out.content_type = "application/octet-stream";
  out.body = encode_binary(d);
  return out;
}

ApiResponse Api::edit(const ApiRequest& r) {
  const Json body = parse_body(r.body);
  const std::string op = member(body, "op").as_string("\"op\"");
  const MeshWanted mesh = mesh_wanted(r);
  const std::uint64_t base = session_.constraint_version();
  std::string extra = "\"op\":" + json_quote(op);
  if (op == "add") {
    check_keys(body, {"op", "position", "value"});
    const std::size_t i = session_.add(point_member(body, "position"), finite_number(body, "value"));
    extra += ",\"index\":" + std::to_string(i);
  } else if (op == "move") {
    check_keys(body, {"op", "index", "position", "merge"});
    session_.move(index_member(body, "index"), point_member(body, "position"),
                  bool_member(body, "merge", false));
  } else if (op == "remove") {
    check_keys(body, {"op", "index"});
    session_.remove(index_member(body, "index"));
  } else if (op == "value") {
    check_keys(body, {"op", "index", "value"});
    session_.set_value(index_member(body, "index"), finite_number(body, "value"));
  } else {
    throw BadRequest("unknown edit \"" + op + "\" (add, move, remove, value)");
  }
  return with_mesh(mesh, stats_json(extra + changes_since(base)));
}

ApiResponse Api::refine(const ApiRequest& r) {
  const Json body = parse_body(r.body);
  check_keys(body, {"precision", "all"});
  if (body.find("precision")) {
    const double p = finite_number(body, "precision");
    if (!(p > 0) || p > 1) throw BadRequest("\"precision\" must be in (0, 1] (a fraction of the diagonal)");
    session_.set_precision(p);
  }
  bool stepped = false;
  if (bool_member(body, "all", false)) {
    while (session_.refine_step()) stepped = true;
  } else {
    stepped = session_.refine_step([this] { return waiting_.load() == 0; });
  }
  return json_response(stats_json(std::string("\"stepped\":") + (stepped ? "true" : "false")));
}

ApiResponse Api::load(const ApiRequest& r) {
  const std::string name = param(r, "name");
  if (name.empty() || name.size() > 200) throw BadRequest("\"name\" (the uploaded file's name) is required");
  const std::string ext = file_extension(name);
  // (.laz is taken to be refused by the reader, which says how to decompress it.)
  if (ext != "xyzv" && ext != "xyz" && ext != "pwn" && ext != "pcd" && ext != "las" && ext != "laz" && ext != "off" &&
      ext != "obj" && ext != "ply" && ext != "stl")
    throw BadRequest("cannot open '." + ext + "' files (.xyzv, .xyz, .pwn, .pcd, .las, .off, .obj, .ply, .stl)");
  if (r.body.empty()) throw BadRequest(name + ": empty file");
  // Points are read as vitri mesh reads a scan; "viewpoint=X,Y,Z" plays its --viewpoint (else the
  // file's own, a PCD VIEWPOINT).
  ScanOptions scan = scan_;
  const std::string viewpoint = param(r, "viewpoint");
  if (!viewpoint.empty()) {
    double xyz[3];
    const char* at = viewpoint.c_str();
    for (int k = 0; k < 3; ++k) {
      char* end = nullptr;
      xyz[k] = std::strtod(at, &end);
      if (end == at || !std::isfinite(xyz[k]) || *end != (k < 2 ? ',' : '\0'))
        throw BadRequest("\"viewpoint\" must be three finite numbers X,Y,Z, got '" + viewpoint + "'");
      at = end + (k < 2);
    }
    scan.viewpoint = Point3{xyz[0], xyz[1], xyz[2]};
  }
  // Parsed from memory: the server never opens a path a client names.
  Input in = parse_input(r.body, name);
  cli::repair_mesh(in, name, "vitri studio");  // as vitri mesh: no-area triangles, a soup's vertices
  const bool points = cli::is_scan(in);
  ScanFit fit;
  Constraints c = cli::constraints_of(std::move(in), name, build_, nullptr, scan, &fit);
  session_.load(std::move(c), name);
  return json_response(stats_json(points ? "\"scan\":" + json_quote(cli::describe_scan(fit, !viewpoint.empty())) : ""));
}

ApiResponse Api::export_file(const ApiRequest& r) {
  const std::string format = param(r, "format");
  const std::string path = temp_path(format);
  if (format == "xyzv") {
    const Constraints& c = session_.mesher().constraints();
    write_xyzv(path, PointValues{c.points, c.values});
  } else if (format == "obj" || format == "ply" || format == "off" || format == "stl") {
    session_.settle();  // the target mesh, with every edit (not the preview)
    write_mesh(path, cli::view_of(session_.mesher().surface()));
  } else {
    throw BadRequest("\"format\" must be xyzv, obj, ply, off or stl, got '" + format + "'");
  }
  ApiResponse out;
  out.content_type = format == "ply" || format == "stl" ? "application/octet-stream" : "text/plain";
  out.body = read_whole_file(path);
  std::remove(path.c_str());
  out.download = download_name(session_.name(), format);
  return out;
}

}  // namespace vitri::studio
