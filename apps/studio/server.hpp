#pragma once
// The studio's HTTP server (cpp-httplib): the API under /api/ and the page's files (our web/ folder and
// three.js from its installed location). Binds 127.0.0.1 unless told otherwise.
#include "api.hpp"

#include <cstddef>
#include <memory>
#include <string>

namespace vitri::studio {

struct ServerOptions {
  std::string host = "127.0.0.1";    ///< address to bind; another one exposes the studio to the network
  int port = 8080;                   ///< 0: any free port (see Server::port())
  std::string web_dir;               ///< folder with index.html, studio.js, studio.css
  std::string three_dir;             ///< three.js installation (build/three.min.js, examples/js/controls/)
  std::size_t max_body = 64u << 20;  ///< largest request body (an uploaded file); larger gets 413
  /// The WebSocket transport (socket.hpp) on a second port of the same host, which the page uses for
  /// its requests when it can (`socket_port` in the stats); false: HTTP only.
  bool socket = true;
  int socket_port = 0;  ///< 0: any free port
};

/// The files the server serves besides the API: URL path -> file on disk (never a client-given path).
struct StaticFile {
  std::string url;
  std::string path;
  std::string content_type;
};
std::vector<StaticFile> static_files(const ServerOptions& options);

class SocketServer;

class Server {
 public:
  Server(Api& api, const ServerOptions& options);
  ~Server();
  Server(const Server&) = delete;
  Server& operator=(const Server&) = delete;
  /// Binds the address (and the socket's, see ServerOptions::socket). @return the HTTP port.
  /// @throws vitri::Error when it cannot bind.
  int bind();
  /// Serves until stop() (from another thread or a signal-waiting thread). @pre bind() succeeded.
  void run();
  void stop();
  int port() const { return port_; }
  /// The WebSocket's port (0 without it).
  int socket_port() const;

 private:
  struct Impl;
  Api& api_;
  std::unique_ptr<Impl> impl_;
  ServerOptions options_;
  int port_ = 0;
};

}  // namespace vitri::studio
