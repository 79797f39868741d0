#pragma once
// The studio's WebSocket transport (RFC 6455), beside the HTTP server: the page sends its API requests
// over one socket and gets each answer as one binary message, without a fetch per update (a fetch costs
// the page 2.7-4.6 ms on localhost, a socket message 0.3-0.4 ms: docs/studio.md). The same Api serves
// both; the messages carry the HTTP API's requests and answers unchanged (docs/studio.md, "Socket").
//
// Request: one text (or binary) message "ID METHOD TARGET\n" then the body, with ID a decimal in
// 1..2^32-1 chosen by the client, TARGET the API path with its query ("/api/edit?mesh=3&exact=0").
// Answer: one binary message, little-endian: uint32 ID (0 when the request line could not be read),
// uint32 status, float32 server milliseconds (the Server-Timing value; -1: none), uint32 L, L bytes of
// content type padded with spaces to a multiple of 4, then the body. Requests of one connection run
// concurrently (each on its own thread, as HTTP requests do), so a waiting edit interrupts a refinement
// step; the Api serializes them. Answers may come in another order than the requests.
//
// Only what the page needs: no extensions, no subprotocols; masked client frames, fragments joined,
// ping answered, close echoed. Bad handshakes get an HTTP error; bad frames close with the RFC's code.
#include "api.hpp"

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <list>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <thread>

namespace vitri::studio {

/// Sec-WebSocket-Accept for a client's Sec-WebSocket-Key: base64(SHA-1(key + RFC 6455's GUID)).
std::string websocket_accept(const std::string& key);
/// SHA-1 of `data` (FIPS 180-4), 20 bytes. Only for the handshake above.
std::string sha1(const std::string& data);
/// Standard base64 with padding.
std::string base64(const std::string& data);

/// Whether a browser page of origin `origin` ("http://host:port", the Origin header) may use the API of
/// a studio whose page is served on `http_port`. Scripts send no Origin (empty: allowed). A page must
/// come from the studio itself: its port, and a loopback name (127.0.0.1, localhost, [::1]) when the
/// server binds a loopback address, else the host name the request was sent to (`host_header`, the
/// Host header without its port). Another site's page (cross-site requests, DNS rebinding) is refused.
bool origin_allowed(const std::string& origin, const std::string& bound_host, int http_port,
                    const std::string& host_header);

/// "k=v&k2=v2" -> parameters (percent-decoded, '+' as space; the first of repeated keys kept).
/// @return false on a malformed escape.
bool parse_query(const std::string& query, std::map<std::string, std::string>& out);

struct SocketOptions {
  std::string host = "127.0.0.1";     ///< address to bind (the HTTP server's)
  int port = 0;                       ///< 0: any free port
  int http_port = 0;                  ///< the page's port (Origin check)
  std::size_t max_message = 64u << 20;  ///< largest request message; larger closes with 1009
  std::size_t max_connections = 16;   ///< beyond: the handshake gets 503
  std::size_t max_in_flight = 8;      ///< requests of one connection running at once; beyond: 503
};

class SocketServer {
 public:
  SocketServer(Api& api, const SocketOptions& options);
  ~SocketServer();
  SocketServer(const SocketServer&) = delete;
  SocketServer& operator=(const SocketServer&) = delete;
  /// Binds and listens. @return the port. @throws vitri::Error when it cannot bind.
  int bind();
  /// Accepts connections on a thread of its own until stop() (nothing after a stop()).
  /// @pre bind() succeeded.
  void start();
  /// Closes the listening socket and every connection; waits for their threads.
  void stop();
  int port() const { return port_; }

 private:
  struct Connection;
  struct Frame {
    bool fin = false;
    int opcode = 0;
    std::string payload;
  };
  void accept_loop();
  static int read_frame(Connection& c, bool in_message, std::size_t room, Frame& f);
  void serve(Connection& c);
  bool handshake(Connection& c);
  void answer(Connection& c, std::uint32_t id, const ApiResponse& r);
  void handle_message(Connection& c, std::string message);
  void reap_finished();

  Api& api_;
  SocketOptions options_;
  int listen_fd_ = -1;
  int port_ = 0;
  std::atomic<bool> stopping_{false};
  std::thread acceptor_;
  std::mutex mutex_;  // guards connections_
  std::list<std::unique_ptr<Connection>> connections_;
};

}  // namespace vitri::studio
