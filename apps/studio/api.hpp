#pragma once
// The studio's HTTP/JSON API, independent of the HTTP library: a request (method, path, query
// parameters, body) goes in, a response (status, type, body, download name) comes out. Every request is
// validated before the session changes; a bad one gets a 4xx status and {"error": "..."} and changes
// nothing. Endpoints and formats: docs/studio.md.
#include "session.hpp"

#include <atomic>
#include <map>
#include <mutex>
#include <string>

namespace vitri::studio {

/// The mesh delta an edit's answer carries (query parameters "mesh", the client's mesh version, and
/// "exact", 0 or 1): none unless `wanted`.
struct MeshWanted {
  bool wanted = false;
  std::uint32_t since = 0;
  bool exact = true;
};

struct ApiRequest {
  std::string method;                         ///< "GET", "POST", ...
  std::string path;                           ///< e.g. "/api/edit"
  std::map<std::string, std::string> params;  ///< query parameters
  std::string body;
};

struct ApiResponse {
  int status = 200;
  std::string content_type = "application/json";
  std::string body;
  std::string download;   ///< non-empty: offer the body as a file of this name (Content-Disposition)
  double server_ms = -1;  ///< time the session spent on it (after waiting for earlier requests); < 0: none
};

/// A response {"error": what} with the given status.
ApiResponse error_response(int status, const std::string& what);

/// Serves the API over one session. Thread-safe: requests are serialized; a refinement step in progress
/// gives way to a waiting edit (it stops between insertions and resumes on the next refine request).
class Api {
 public:
  /// `build` turns an uploaded mesh or points into constraints (vitri mesh's --offset, --sides); uploaded
  /// points are read as vitri mesh reads a scan, with `scan` (its k; the viewpoint is the file's or the
  /// request's, docs/studio.md).
  Api(Session& session, const ConstraintBuildOptions& build = {}, const ScanOptions& scan = {});
  ~Api();
  Api(const Api&) = delete;
  Api& operator=(const Api&) = delete;

  /// Answers one request; never throws.
  ApiResponse handle(const ApiRequest& request);
  /// True when the path is an API route (the server serves the page's files for the others).
  static bool is_api_path(const std::string& path);
  /// The WebSocket transport's port, shown in the stats as `socket_port` (0: none, `null`).
  void set_socket_port(int port) { socket_port_ = port; }

 private:
  ApiResponse route(const ApiRequest& request);
  ApiResponse stats();
  ApiResponse state();
  ApiResponse mesh(const ApiRequest& request);
  ApiResponse edit(const ApiRequest& request);
  ApiResponse refine(const ApiRequest& request);
  ApiResponse load(const ApiRequest& request);
  ApiResponse export_file(const ApiRequest& request);
  ApiResponse with_mesh(const MeshWanted& mesh, std::string json);
  std::string stats_json(const std::string& extra = {});
  std::string changes_since(std::uint64_t base) const;
  std::string temp_path(const std::string& ext) const;

  Session& session_;
  ConstraintBuildOptions build_;
  ScanOptions scan_;
  std::mutex mutex_;
  std::atomic<int> waiting_{0};
  std::atomic<int> socket_port_{0};  // requests waiting for the mutex (a refinement step yields to them)
  std::string temp_dir_;         // private (0700) directory for exports, removed by the destructor
};

}  // namespace vitri::studio
