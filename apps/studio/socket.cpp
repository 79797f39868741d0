// The studio's WebSocket transport (socket.hpp; RFC 6455 sections 4 and 5; docs/studio.md, "Socket").
#include "socket.hpp"

#include "vitri/core/error.hpp"

#include <arpa/inet.h>
#include <netdb.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <sys/socket.h>
#include <sys/time.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <cerrno>
#include <cstring>
#include <vector>

namespace vitri::studio {
namespace {

// ---- SHA-1 (FIPS 180-4, section 6.1) and base64: the handshake's accept key only.
std::uint32_t rotl(std::uint32_t x, int n) {
  return (x << n) | (x >> (32 - n));
}

void sha1_block(std::array<std::uint32_t, 5>& h, const unsigned char* p) {
  std::uint32_t w[80];
  for (int t = 0; t < 16; ++t)
    w[t] = (std::uint32_t(p[4 * t]) << 24) | (std::uint32_t(p[4 * t + 1]) << 16) |
           (std::uint32_t(p[4 * t + 2]) << 8) | std::uint32_t(p[4 * t + 3]);
  for (int t = 16; t < 80; ++t) w[t] = rotl(w[t - 3] ^ w[t - 8] ^ w[t - 14] ^ w[t - 16], 1);
  std::uint32_t a = h[0], b = h[1], c = h[2], d = h[3], e = h[4];
  for (int t = 0; t < 80; ++t) {
    std::uint32_t f, k;
    if (t < 20) {
      f = (b & c) | (~b & d);
      k = 0x5a827999u;
    } else if (t < 40) {
      f = b ^ c ^ d;
      k = 0x6ed9eba1u;
    } else if (t < 60) {
      f = (b & c) | (b & d) | (c & d);
      k = 0x8f1bbcdcu;
    } else {
      f = b ^ c ^ d;
      k = 0xca62c1d6u;
    }
    const std::uint32_t next = rotl(a, 5) + f + e + k + w[t];
    e = d;
    d = c;
    c = rotl(b, 30);
    b = a;
    a = next;
  }
  h[0] += a;
  h[1] += b;
  h[2] += c;
  h[3] += d;
  h[4] += e;
}

// ---- Sockets
bool send_all(int fd, const char* p, std::size_t n, int flags = 0) {
  while (n > 0) {
    const ssize_t k = ::send(fd, p, n, flags | MSG_NOSIGNAL);
    if (k < 0 && errno == EINTR) continue;
    if (k <= 0) return false;
    p += k;
    n -= static_cast<std::size_t>(k);
  }
  return true;
}

void set_receive_timeout(int fd, int seconds) {
  timeval tv{};
  tv.tv_sec = seconds;
  setsockopt(fd, SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof tv);
}

std::string lower(std::string s) {
  for (char& ch : s) ch = static_cast<char>(std::tolower(static_cast<unsigned char>(ch)));
  return s;
}

std::string trim(const std::string& s) {
  const auto b = s.find_first_not_of(" \t");
  if (b == std::string::npos) return {};
  return s.substr(b, s.find_last_not_of(" \t") - b + 1);
}

// Whether the comma-separated header value holds `token` (case-insensitive).
bool has_token(const std::string& value, const std::string& token) {
  std::size_t at = 0;
  const std::string v = lower(value);
  while (at <= v.size()) {
    const std::size_t comma = std::min(v.find(',', at), v.size());
    if (trim(v.substr(at, comma - at)) == token) return true;
    at = comma + 1;
  }
  return false;
}

// "host:port", "[v6]:port" or "host" -> host (brackets kept) and port (-1 when absent). False when the
// port is not 1-5 digits or a bracket is not closed.
bool split_host_port(const std::string& s, std::string& host, int& port) {
  port = -1;
  std::size_t colon = std::string::npos;
  if (!s.empty() && s[0] == '[') {
    const std::size_t close = s.find(']');
    if (close == std::string::npos) return false;
    host = s.substr(0, close + 1);
    if (close + 1 < s.size()) {
      if (s[close + 1] != ':') return false;
      colon = close + 1;
    }
  } else {
    colon = s.rfind(':');
    host = s.substr(0, colon);
  }
  if (colon == std::string::npos) return true;
  const std::string digits = s.substr(colon + 1);
  if (digits.empty() || digits.size() > 5 ||
      !std::all_of(digits.begin(), digits.end(), [](char ch) { return ch >= '0' && ch <= '9'; }))
    return false;
  port = std::stoi(digits);
  return true;
}

// localhost, ::1 or an IPv4 address 127.x.y.z written in digits (a name such as "127.example.com" is
// not: it could resolve anywhere).
bool is_loopback_name(const std::string& host) {
  if (host == "localhost" || host == "[::1]" || host == "::1") return true;
  int dots = 0;
  for (const char ch : host) {
    if (ch == '.') ++dots;
    else if (ch < '0' || ch > '9') return false;
  }
  return dots == 3 && host.rfind("127.", 0) == 0;
}

int hex_digit(char ch) {
  if (ch >= '0' && ch <= '9') return ch - '0';
  if (ch >= 'a' && ch <= 'f') return ch - 'a' + 10;
  if (ch >= 'A' && ch <= 'F') return ch - 'A' + 10;
  return -1;
}

bool percent_decode(const std::string& s, std::string& out) {
  out.clear();
  for (std::size_t i = 0; i < s.size(); ++i) {
    if (s[i] == '+') {
      out.push_back(' ');
    } else if (s[i] == '%') {
      if (i + 2 >= s.size()) return false;
      const int hi = hex_digit(s[i + 1]), lo = hex_digit(s[i + 2]);
      if (hi < 0 || lo < 0) return false;
      out.push_back(static_cast<char>(16 * hi + lo));
      i += 2;
    } else {
      out.push_back(s[i]);
    }
  }
  return true;
}

std::string http_error(int status, const char* reason, const std::string& what, const std::string& extra = {}) {
  const std::string body = "{\"error\":\"" + what + "\"}";  // `what` is ours: no quotes to escape
  return "HTTP/1.1 " + std::to_string(status) + " " + reason +
         "\r\nContent-Type: application/json\r\nContent-Length: " + std::to_string(body.size()) + "\r\n" + extra +
         "Connection: close\r\n\r\n" + body;
}

// Frame opcodes and close codes (RFC 6455 5.2, 7.4.1).
constexpr int kContinuation = 0x0, kText = 0x1, kBinary = 0x2, kClose = 0x8, kPing = 0x9, kPong = 0xA;
constexpr int kProtocolError = 1002, kTooBig = 1009;
constexpr int kEnd = -1;  // read_frame(): the stream ended (or failed) before a whole frame

// The header of an unmasked server frame with FIN set.
std::string frame_header(int opcode, std::size_t n) {
  std::string h;
  h.push_back(static_cast<char>(0x80 | opcode));
  if (n < 126) {
    h.push_back(static_cast<char>(n));
  } else if (n < 65536) {
    h.push_back(static_cast<char>(126));
    h.push_back(static_cast<char>((n >> 8) & 0xff));
    h.push_back(static_cast<char>(n & 0xff));
  } else {
    h.push_back(static_cast<char>(127));
    for (int k = 7; k >= 0; --k) h.push_back(static_cast<char>((std::uint64_t(n) >> (8 * k)) & 0xff));
  }
  return h;
}

void append_u32(std::string& out, std::uint32_t v) {
  for (int k = 0; k < 4; ++k) out.push_back(static_cast<char>((v >> (8 * k)) & 0xffu));
}

}  // namespace

std::string sha1(const std::string& data) {
  std::array<std::uint32_t, 5> h = {0x67452301u, 0xefcdab89u, 0x98badcfeu, 0x10325476u, 0xc3d2e1f0u};
  std::string m = data;
  const std::uint64_t bits = std::uint64_t(data.size()) * 8;
  m.push_back(static_cast<char>(0x80));
  while (m.size() % 64 != 56) m.push_back('\0');
  for (int k = 7; k >= 0; --k) m.push_back(static_cast<char>((bits >> (8 * k)) & 0xff));
  for (std::size_t at = 0; at < m.size(); at += 64)
    sha1_block(h, reinterpret_cast<const unsigned char*>(m.data() + at));
  std::string out;
  for (const std::uint32_t v : h)
    for (int k = 3; k >= 0; --k) out.push_back(static_cast<char>((v >> (8 * k)) & 0xff));
  return out;
}

std::string base64(const std::string& data) {
  static const char* kAlphabet = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  for (std::size_t i = 0; i < data.size(); i += 3) {
    std::uint32_t v = std::uint32_t(static_cast<unsigned char>(data[i])) << 16;
    if (i + 1 < data.size()) v |= std::uint32_t(static_cast<unsigned char>(data[i + 1])) << 8;
    if (i + 2 < data.size()) v |= static_cast<unsigned char>(data[i + 2]);
    out.push_back(kAlphabet[(v >> 18) & 63]);
    out.push_back(kAlphabet[(v >> 12) & 63]);
    out.push_back(i + 1 < data.size() ? kAlphabet[(v >> 6) & 63] : '=');
    out.push_back(i + 2 < data.size() ? kAlphabet[v & 63] : '=');
  }
  return out;
}

std::string websocket_accept(const std::string& key) {
  return base64(sha1(key + "258EAFA5-E914-47DA-95CA-C5AB0DC85B11"));
}

bool origin_allowed(const std::string& origin, const std::string& bound_host, int http_port,
                    const std::string& host_header) {
  if (origin.empty()) return true;  // not a browser page (a script, curl)
  const std::string o = lower(origin);
  const std::string scheme = "http://";
  if (o.rfind(scheme, 0) != 0) return false;  // "null", https, file: never the studio's page
  std::string host;
  int port = -1;
  const std::string rest = o.substr(scheme.size());
  if (rest.find('/') != std::string::npos) return false;
  if (!split_host_port(rest, host, port)) return false;
  if (port < 0) port = 80;
  if (port != http_port || host.empty()) return false;
  if (is_loopback_name(lower(bound_host))) return is_loopback_name(host);
  std::string expected;
  int ignored = -1;
  return split_host_port(lower(host_header), expected, ignored) && !expected.empty() && host == expected;
}

bool parse_query(const std::string& query, std::map<std::string, std::string>& out) {
  std::size_t at = 0;
  while (at < query.size()) {
    const std::size_t amp = std::min(query.find('&', at), query.size());
    const std::string pair = query.substr(at, amp - at);
    at = amp + 1;
    if (pair.empty()) continue;
    const std::size_t eq = pair.find('=');
    std::string k, v;
    if (!percent_decode(pair.substr(0, eq), k)) return false;
    if (eq != std::string::npos && !percent_decode(pair.substr(eq + 1), v)) return false;
    out.emplace(k, v);  // the first of repeated keys, as the HTTP server
  }
  return true;
}

// ---- Server
struct SocketServer::Connection {
  int fd = -1;
  std::thread reader;
  std::atomic<bool> finished{false};  // the reader returned (the acceptor or stop() joins it)
  std::string host_header;
  std::string inbuf;  // bytes read past the handshake
  std::size_t inpos = 0;
  std::mutex write_mutex;  // one message at a time on the socket
  bool closed = false;     // a close frame went out: no data frame may follow (guarded by write_mutex)
  struct Worker {
    std::thread thread;
    std::shared_ptr<std::atomic<bool>> done;
  };
  std::vector<Worker> workers;  // the reader's only (requests running or finished, not joined)

  bool read_exact(void* out, std::size_t n) {
    auto* p = static_cast<char*>(out);
    const std::size_t buffered = std::min(n, inbuf.size() - inpos);
    std::memcpy(p, inbuf.data() + inpos, buffered);
    inpos += buffered;
    p += buffered;
    n -= buffered;
    while (n > 0) {
      const ssize_t k = ::recv(fd, p, n, 0);
      if (k < 0 && errno == EINTR) continue;
      if (k <= 0) return false;
      p += k;
      n -= static_cast<std::size_t>(k);
    }
    return true;
  }
  bool send_frame(int opcode, const std::string& payload) {
    const std::lock_guard<std::mutex> lock(write_mutex);
    if (closed) return false;
    if (opcode == kClose) closed = true;
    return send_text(fd, frame_header(opcode, payload.size()) + payload);
  }
  static bool send_text(int fd, const std::string& s) { return studio::send_all(fd, s.data(), s.size()); }
  void close_with(int code) {
    std::string payload;
    payload.push_back(static_cast<char>((code >> 8) & 0xff));
    payload.push_back(static_cast<char>(code & 0xff));
    send_frame(kClose, payload);
  }
  void join_finished_workers() {
    for (auto it = workers.begin(); it != workers.end();) {
      if (it->done->load()) {
        it->thread.join();
        it = workers.erase(it);
      } else {
        ++it;
      }
    }
  }
  void join_workers() {
    for (Worker& w : workers) w.thread.join();
    workers.clear();
  }
};

SocketServer::SocketServer(Api& api, const SocketOptions& options) : api_(api), options_(options) {}

SocketServer::~SocketServer() {
  stop();
}

int SocketServer::bind() {
  addrinfo hints{};
  hints.ai_family = AF_UNSPEC;
  hints.ai_socktype = SOCK_STREAM;
  hints.ai_flags = AI_PASSIVE | AI_NUMERICSERV;
  addrinfo* found = nullptr;
  const std::string service = std::to_string(options_.port);
  if (getaddrinfo(options_.host.c_str(), service.c_str(), &hints, &found) != 0 || !found)
    throw Error("studio socket: cannot resolve " + options_.host);
  int fd = -1;
  for (addrinfo* a = found; a && fd < 0; a = a->ai_next) {
    fd = ::socket(a->ai_family, a->ai_socktype | SOCK_CLOEXEC, a->ai_protocol);
    if (fd < 0) continue;
    int yes = 1;
    setsockopt(fd, SOL_SOCKET, SO_REUSEADDR, &yes, sizeof yes);
    if (::bind(fd, a->ai_addr, a->ai_addrlen) != 0 || ::listen(fd, 16) != 0) {
      ::close(fd);
      fd = -1;
    }
  }
  freeaddrinfo(found);
  if (fd < 0)
    throw Error("studio socket: cannot bind " + options_.host + ":" + service + " (" + std::strerror(errno) + ")");
  sockaddr_storage addr{};
  socklen_t len = sizeof addr;
  getsockname(fd, reinterpret_cast<sockaddr*>(&addr), &len);
  port_ = ntohs(addr.ss_family == AF_INET6 ? reinterpret_cast<sockaddr_in6*>(&addr)->sin6_port
                                           : reinterpret_cast<sockaddr_in*>(&addr)->sin_port);
  listen_fd_ = fd;
  return port_;
}

void SocketServer::start() {
  const std::lock_guard<std::mutex> lock(mutex_);  // stop() may run on another thread (a signal)
  if (stopping_.load()) return;  // stopped before it started (a signal right after the bind)
  if (listen_fd_ < 0) throw Error("studio socket: start() before bind()");
  acceptor_ = std::thread([this] { accept_loop(); });
}

void SocketServer::stop() {
  if (stopping_.exchange(true)) return;
  if (listen_fd_ >= 0) ::shutdown(listen_fd_, SHUT_RDWR);  // accept() returns
  std::thread acceptor;
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    acceptor.swap(acceptor_);
  }
  if (acceptor.joinable()) acceptor.join();
  if (listen_fd_ >= 0) ::close(listen_fd_);
  listen_fd_ = -1;
  std::list<std::unique_ptr<Connection>> all;
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    all.swap(connections_);
  }
  for (auto& c : all) ::shutdown(c->fd, SHUT_RDWR);  // the readers see the end of the stream
  for (auto& c : all) {
    c->reader.join();
    ::close(c->fd);
  }
}

void SocketServer::reap_finished() {
  const std::lock_guard<std::mutex> lock(mutex_);
  for (auto it = connections_.begin(); it != connections_.end();) {
    if ((*it)->finished.load()) {
      (*it)->reader.join();
      ::close((*it)->fd);
      it = connections_.erase(it);
    } else {
      ++it;
    }
  }
}

void SocketServer::accept_loop() {
  while (!stopping_.load()) {
    const int fd = ::accept4(listen_fd_, nullptr, nullptr, SOCK_CLOEXEC);
    if (fd < 0) {
      if (stopping_.load()) break;
      if (errno == EINTR || errno == ECONNABORTED) continue;
      if (errno == EMFILE || errno == ENFILE || errno == ENOBUFS || errno == ENOMEM) {
        std::this_thread::sleep_for(std::chrono::milliseconds(20));  // the reaping below may free some
        reap_finished();
        continue;
      }
      break;
    }
    reap_finished();
    int yes = 1;
    setsockopt(fd, IPPROTO_TCP, TCP_NODELAY, &yes, sizeof yes);  // an answer goes out at once
    const std::lock_guard<std::mutex> lock(mutex_);
    if (connections_.size() >= options_.max_connections) {
      const std::string busy = http_error(503, "Service Unavailable", "too many socket connections");
      send_all(fd, busy.data(), busy.size());
      ::close(fd);
      continue;
    }
    connections_.push_back(std::make_unique<Connection>());
    Connection* c = connections_.back().get();
    c->fd = fd;
    c->reader = std::thread([this, c] {
      serve(*c);
      c->finished = true;
    });
  }
}

bool SocketServer::handshake(Connection& c) {
  constexpr std::size_t kMaxHeaders = 16384;
  std::string req;
  std::size_t end = std::string::npos;
  char buf[4096];
  while ((end = req.find("\r\n\r\n")) == std::string::npos && req.size() <= kMaxHeaders) {
    const ssize_t k = ::recv(c.fd, buf, sizeof buf, 0);
    if (k < 0 && errno == EINTR) continue;
    if (k <= 0) return false;
    req.append(buf, static_cast<std::size_t>(k));
  }
  if (end == std::string::npos || end > kMaxHeaders) {
    Connection::send_text(c.fd, http_error(431, "Request Header Fields Too Large", "handshake over 16 KiB"));
    return false;
  }
  c.inbuf = req.substr(end + 4);
  req.resize(end);
  const auto fail = [&](int status, const char* reason, const std::string& what, const std::string& extra = {}) {
    Connection::send_text(c.fd, http_error(status, reason, "socket handshake: " + what, extra));
    return false;
  };
  std::size_t line_end = req.find("\r\n");
  const std::string request_line = req.substr(0, line_end);
  std::map<std::string, std::string> headers;
  while (line_end != std::string::npos) {
    const std::size_t next = req.find("\r\n", line_end + 2);
    const std::string line = req.substr(line_end + 2, next == std::string::npos ? std::string::npos : next - line_end - 2);
    line_end = next;
    const std::size_t colon = line.find(':');
    if (colon == std::string::npos || colon == 0) return fail(400, "Bad Request", "malformed header line");
    const std::string name = lower(line.substr(0, colon)), value = trim(line.substr(colon + 1));
    auto [it, fresh] = headers.emplace(name, value);
    if (!fresh) it->second += ", " + value;
  }
  const auto header = [&](const char* name) {
    const auto it = headers.find(name);
    return it == headers.end() ? std::string() : it->second;
  };
  const std::size_t s1 = request_line.find(' '), s2 = request_line.rfind(' ');
  if (s1 == std::string::npos || s2 == s1 || request_line.substr(s2 + 1) != "HTTP/1.1")
    return fail(400, "Bad Request", "the request line must be 'GET /api/socket HTTP/1.1'");
  if (request_line.substr(0, s1) != "GET") return fail(405, "Method Not Allowed", "GET only");
  if (request_line.substr(s1 + 1, s2 - s1 - 1) != "/api/socket") return fail(404, "Not Found", "the path is /api/socket");
  if (!has_token(header("upgrade"), "websocket") || !has_token(header("connection"), "upgrade"))
    return fail(400, "Bad Request", "not a WebSocket upgrade (Upgrade: websocket, Connection: Upgrade)");
  if (header("sec-websocket-version") != "13")
    return fail(426, "Upgrade Required", "Sec-WebSocket-Version must be 13", "Sec-WebSocket-Version: 13\r\n");
  const std::string key = header("sec-websocket-key");
  const bool key_ok = key.size() == 24 && key.compare(22, 2, "==") == 0 &&
                      std::all_of(key.begin(), key.begin() + 22, [](char ch) {
                        return std::isalnum(static_cast<unsigned char>(ch)) || ch == '+' || ch == '/';
                      });
  if (!key_ok) return fail(400, "Bad Request", "Sec-WebSocket-Key must be 16 bytes in base64");
  c.host_header = header("host");
  if (!origin_allowed(header("origin"), options_.host, options_.http_port, c.host_header))
    return fail(403, "Forbidden", "a page of another origin may not use the studio");
  return Connection::send_text(c.fd, "HTTP/1.1 101 Switching Protocols\r\nUpgrade: websocket\r\n"
                                    "Connection: Upgrade\r\nSec-WebSocket-Accept: " +
                                        websocket_accept(key) + "\r\n\r\n");
}

// One client frame, unmasked. Returns 0, kEnd (the stream ended) or the close code of a frame no browser
// sends: masked frames only; no RSV bit (no extension was negotiated); control frames whole and short; a
// continuation continues a message, a text or binary frame starts one (`in_message`); a data frame over
// `room` bytes is refused from its header, before its payload is read.
int SocketServer::read_frame(Connection& c, bool in_message, std::size_t room, Frame& f) {
  unsigned char h[2];
  if (!c.read_exact(h, 2)) return kEnd;
  f.fin = (h[0] & 0x80) != 0;
  f.opcode = h[0] & 0x0f;
  const bool masked = (h[1] & 0x80) != 0;
  std::uint64_t len = h[1] & 0x7f;
  if (len >= 126) {
    unsigned char e[8];
    const std::size_t k = len == 126 ? 2 : 8;
    if (!c.read_exact(e, k)) return kEnd;
    len = 0;
    for (std::size_t i = 0; i < k; ++i) len = (len << 8) | e[i];
  }
  const bool control = (f.opcode & 0x8) != 0;
  const bool known = f.opcode == kContinuation || f.opcode == kText || f.opcode == kBinary ||
                     f.opcode == kClose || f.opcode == kPing || f.opcode == kPong;
  if ((h[0] & 0x70) != 0 || !masked || !known || (control && (!f.fin || len > 125)) ||
      (f.opcode == kContinuation && !in_message) || ((f.opcode == kText || f.opcode == kBinary) && in_message))
    return kProtocolError;
  if (!control && len > room) return kTooBig;
  unsigned char mask[4];
  if (!c.read_exact(mask, 4)) return kEnd;
  f.payload.assign(static_cast<std::size_t>(len), '\0');
  if (len > 0 && !c.read_exact(&f.payload[0], f.payload.size())) return kEnd;
  for (std::size_t i = 0; i < f.payload.size(); ++i) f.payload[i] = static_cast<char>(f.payload[i] ^ mask[i % 4]);
  return 0;
}

void SocketServer::serve(Connection& c) {
  set_receive_timeout(c.fd, 10);  // a client that opens a connection and says nothing
  const bool open = handshake(c);
  set_receive_timeout(c.fd, 0);
  if (!open) {
    ::shutdown(c.fd, SHUT_WR);
    return;
  }
  std::string message;
  bool in_message = false;
  for (;;) {
    Frame f;
    const int status = read_frame(c, in_message, options_.max_message - message.size(), f);
    if (status == kEnd) break;
    if (status != 0) {
      c.close_with(status);
      break;
    }
    if (f.opcode == kClose) {  // echo the code (RFC 6455 5.5.1), then the connection ends
      c.send_frame(kClose, f.payload.substr(0, std::min<std::size_t>(f.payload.size(), 2)));
      break;
    }
    if (f.opcode == kPing) {
      c.send_frame(kPong, f.payload);
      continue;
    }
    if (f.opcode == kPong) continue;
    message += f.payload;
    in_message = !f.fin;
    if (f.fin) {
      handle_message(c, std::move(message));
      message.clear();
    }
  }
  c.join_workers();
  ::shutdown(c.fd, SHUT_WR);  // the client sees the end now; the descriptor is closed when reaped
}

void SocketServer::handle_message(Connection& c, std::string message) {
  // "ID METHOD TARGET\n" then the body.
  const std::size_t nl = message.find('\n');
  const std::string line = message.substr(0, nl);
  std::uint32_t id = 0;
  ApiRequest r;
  std::string error;
  const std::size_t s1 = line.find(' '), s2 = s1 == std::string::npos ? s1 : line.find(' ', s1 + 1);
  const std::string id_text = line.substr(0, s1);
  const bool digits = !id_text.empty() && id_text.size() <= 10 &&
                      std::all_of(id_text.begin(), id_text.end(), [](char ch) { return ch >= '0' && ch <= '9'; });
  const unsigned long long id_value = digits ? std::stoull(id_text) : 0;
  const bool id_ok = id_value >= 1 && id_value <= 0xffffffffull;
  if (id_ok) id = static_cast<std::uint32_t>(id_value);
  if (nl == std::string::npos || !id_ok || s2 == std::string::npos || line.find(' ', s2 + 1) != std::string::npos) {
    error = "socket request: the first line must be 'ID METHOD TARGET' (ID in 1..4294967295), then the body";
  } else {
    r.method = line.substr(s1 + 1, s2 - s1 - 1);
    const std::string target = line.substr(s2 + 1);
    const std::size_t q = target.find('?');
    r.path = target.substr(0, q);
    r.body = message.substr(nl + 1);
    if (r.method != "GET" && r.method != "POST" && r.method != "PUT" && r.method != "DELETE" && r.method != "PATCH")
      error = "socket request: unknown method '" + r.method + "'";
    else if (!Api::is_api_path(r.path))
      error = "socket request: not an API path: " + r.path;
    else if (q != std::string::npos && !parse_query(target.substr(q + 1), r.params))
      error = "socket request: malformed query in " + target;
  }
  if (!error.empty()) return answer(c, id, error_response(400, error));
  c.join_finished_workers();
  if (c.workers.size() >= options_.max_in_flight)
    return answer(c, id, error_response(503, "socket: more than " + std::to_string(options_.max_in_flight) +
                                                 " requests of one connection at once"));
  // On a thread of its own, as an HTTP request: an edit arriving while a refinement step runs makes it
  // yield (Api::handle), which a reader busy with the step could not.
  auto done = std::make_shared<std::atomic<bool>>(false);
  // A request counts as done before its answer leaves: a client that sends the next one on receiving it
  // never finds the previous one still in flight (joining its thread then waits for the send at most).
  c.workers.push_back({std::thread([this, &c, id, r = std::move(r), done] {
                         const ApiResponse response = api_.handle(r);
                         *done = true;
                         answer(c, id, response);
                       }),
                       done});
}

void SocketServer::answer(Connection& c, std::uint32_t id, const ApiResponse& r) {
  std::string head;
  append_u32(head, id);
  append_u32(head, static_cast<std::uint32_t>(r.status));
  const float ms = r.server_ms >= 0 ? static_cast<float>(r.server_ms) : -1.0f;
  std::uint32_t bits;
  std::memcpy(&bits, &ms, 4);
  append_u32(head, bits);
  std::string type = r.content_type;
  while (type.size() % 4) type.push_back(' ');
  append_u32(head, static_cast<std::uint32_t>(type.size()));
  head += type;
  const std::lock_guard<std::mutex> lock(c.write_mutex);
  if (c.closed) return;  // the client closed (or was closed on) while the request ran: nobody to answer
  const std::string frame = frame_header(kBinary, head.size() + r.body.size()) + head;
  // MSG_MORE: the header and the body leave in the same packets.
  if (studio::send_all(c.fd, frame.data(), frame.size(), MSG_MORE))
    studio::send_all(c.fd, r.body.data(), r.body.size());
}

}  // namespace vitri::studio
