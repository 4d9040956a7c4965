// `lodforge serve DIR`: a tileset directory and the browser viewers over HTTP (cpp-httplib).
// GET and HEAD only, content types for what tilesets and the viewers hold, Range requests and
// compression for text (cpp-httplib; JSON and scripts gzipped once here), an opt-in CORS header,
// loopback unless told otherwise, one log line per request, a clean stop on Ctrl-C. Paths are
// resolved inside their root: "..", absolute paths and symlinks that lead out are refused.
#include <atomic>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <optional>
#include <thread>

#include <fmt/format.h>
#include <httplib.h>
#include <sys/socket.h>
#include <zlib.h>

#include "cli.h"
#include "lodforge/core/file.h"
#include "lodforge/core/progress.h"
#include "serve_paths.h"
#include "serve_ranges.h"

namespace lodforge::cli {

namespace fs = std::filesystem;

namespace {

constexpr std::size_t kWorkers = 128;

struct ServeOptions {
  std::string directory;
  std::string host = "127.0.0.1";
  int port = 8080;
  bool cors = false;
  std::string web;  // the viewers' folder; default: found beside the binary
};

// tileset.json and the viewers' scripts gzipped once per version of the file (cpp-httplib would
// compress them on every request: at 100 connections on 2 cores that cost a third of the
// throughput and some requests timed out). Keyed by path, size and modification time.
class GzipCache {
 public:
  std::shared_ptr<const std::string> get(const fs::path& path, std::span<const std::byte> body) {
    std::error_code error;
    const auto stamp = fs::last_write_time(path, error).time_since_epoch().count();
    std::lock_guard lock(mutex_);
    Entry& entry = entries_[path.string()];
    if (!entry.gzip || entry.stamp != stamp || entry.size != body.size()) {
      entry.gzip = std::make_shared<const std::string>(gzip(body));
      entry.stamp = stamp;
      entry.size = body.size();
    }
    return entry.gzip;
  }

 private:
  static std::string gzip(std::span<const std::byte> data) {
    z_stream z{};
    deflateInit2(&z, Z_BEST_COMPRESSION, Z_DEFLATED, 15 + 16, 9, Z_DEFAULT_STRATEGY);
    std::string out(deflateBound(&z, static_cast<uLong>(data.size())) + 32, '\0');
    z.next_in = reinterpret_cast<Bytef*>(const_cast<std::byte*>(data.data()));
    z.avail_in = static_cast<uInt>(data.size());
    z.next_out = reinterpret_cast<Bytef*>(out.data());
    z.avail_out = static_cast<uInt>(out.size());
    deflate(&z, Z_FINISH);
    out.resize(z.total_out);
    deflateEnd(&z);
    return out;
  }
  struct Entry {
    std::shared_ptr<const std::string> gzip;
    std::int64_t stamp = 0;
    std::size_t size = 0;
  };
  std::mutex mutex_;
  std::map<std::string, Entry> entries_;
};

// Files mapped once per version and handed to the socket from the mapping (no read and no copy
// per request; tiles are read far more often than they change).
class FileCache {
 public:
  std::shared_ptr<const MappedFile> get(const fs::path& path) {
    std::error_code error;
    const auto stamp = fs::last_write_time(path, error).time_since_epoch().count();
    const auto size = fs::file_size(path, error);
    if (error) return nullptr;
    std::lock_guard lock(mutex_);
    Entry& entry = entries_[path.string()];
    if (!entry.file || entry.stamp != stamp || entry.size != size) {
      Result<MappedFile> mapped = MappedFile::open(path.string());
      if (!mapped) return nullptr;
      entry.file = std::make_shared<const MappedFile>(std::move(*mapped));
      entry.stamp = stamp;
      entry.size = size;
    }
    return entry.file;
  }

 private:
  struct Entry {
    std::shared_ptr<const MappedFile> file;
    std::int64_t stamp = 0;
    std::uintmax_t size = 0;
  };
  std::mutex mutex_;
  std::map<std::string, Entry> entries_;
};

struct Caches {
  FileCache files;
  GzipCache gzip;
};

// The types gzipped once per version of the file (GzipCache), as the type they are sent with:
// cpp-httplib would compress them on every request, and a script with brotli at its top quality
// (CesiumJS's 5.6 MB took 10 s, on every page load). The "; charset" form keeps cpp-httplib from
// compressing them again.
std::optional<std::string> compressedOnceType(const std::string& type) {
  if (type == "application/json") return "application/json; charset=utf-8";
  if (type == "text/javascript") return "application/javascript; charset=utf-8";
  return std::nullopt;
}

// cpp-httplib 0.11 cuts Range requests without clamping them to the file: an end past it sends
// a Content-Length it never fills, a start past it underflows. The ranges it parsed are replaced
// by one clamped to the file (RFC 9110 §14.1.2), and one past the end is answered 416 with the
// size. The request is the server's own mutable object, handed to handlers as const.
bool applyRanges(const httplib::Request& request, httplib::Response& response, std::size_t size) {
  if (request.ranges.empty()) return true;
  auto& ranges = const_cast<httplib::Request&>(request).ranges;
  const ServedRanges served = serveRanges({ranges.begin(), ranges.end()}, size);
  ranges.clear();
  if (!served.satisfiable) {
    response.status = 416;
    response.set_header("Content-Range", fmt::format("bytes */{}", size));
    response.set_content("range not satisfiable\n", "text/plain");
    return false;
  }
  // Several ranges would go out as multipart/byteranges, which cpp-httplib 0.11 gets wrong for
  // a streamed body (every part says size 0): the whole file instead, as RFC 9110 §14.2 allows.
  if (served.ranges.size() == 1)
    ranges.emplace_back(static_cast<ssize_t>(served.ranges[0].first),
                        static_cast<ssize_t>(served.ranges[0].second));
  return true;
}

void serveFile(const fs::path& root, const std::string& relative, const httplib::Request& request,
               httplib::Response& response, Caches& caches) {
  const ResolvedPath resolved = resolveInside(root, relative);
  if (resolved.status != 200) {
    response.status = resolved.status;
    response.set_content(resolved.status == 403 ? "forbidden\n" : "not found\n", "text/plain");
    return;
  }
  const std::shared_ptr<const MappedFile> file = caches.files.get(resolved.path);
  if (!file) {
    response.status = 500;
    response.set_content("cannot read the file\n", "text/plain");
    return;
  }
  const auto bytes = file->bytes();
  if (!applyRanges(request, response, bytes.size())) return;
  // cpp-httplib answers Range requests (206) and compresses text types on its own; HEAD drops
  // the body but keeps its length. JSON and scripts are compressed here, once per version.
  const std::string type = contentTypeFor(resolved.path.string());
  // Text is copied into the response (cpp-httplib compresses bodies only); binary is not.
  const auto text = [&] {
    return std::string(reinterpret_cast<const char*>(bytes.data()), bytes.size());
  };
  if (const std::optional<std::string> once = compressedOnceType(type)) {
    response.set_header("Vary", "Accept-Encoding");
    // A range is of the file as it is (identity): no gzip then.
    if (request.ranges.empty() &&
        request.get_header_value("Accept-Encoding").find("gzip") != std::string::npos) {
      response.set_header("Content-Encoding", "gzip");
      response.set_content(*caches.gzip.get(resolved.path, bytes), *once);
      return;
    }
    response.set_content(text(), *once);
    return;
  }
  if (type.starts_with("text/") || type == "image/svg+xml" || type == "application/xml") {
    response.set_content(text(), type);  // cpp-httplib gzips these when asked
    return;
  }
  // Binary contents straight from the mapping (cpp-httplib cuts Range requests from it).
  response.set_content_provider(
      bytes.size(), type, [file](std::size_t offset, std::size_t length, httplib::DataSink& sink) {
        const auto data = file->bytes();
        return sink.write(reinterpret_cast<const char*>(data.data()) + offset, length);
      });
}

// The folder `lodforge tiles -o` wrote, as an absolute path; a usage error for anything else.
Result<fs::path> tilesetRoot(const std::string& directory) {
  std::error_code error;
  const fs::path root = fs::weakly_canonical(directory, error);
  if (error || !fs::is_directory(root, error))
    return Error{
        ErrorKind::kUsage,
        fmt::format("{}: not a directory; give the folder `lodforge tiles -o` wrote", directory)};
  if (!fs::is_regular_file(root / "tileset.json", error))
    return Error{ErrorKind::kUsage,
                 fmt::format("{}: holds no tileset.json; give the folder `lodforge tiles -o` wrote",
                             directory)};
  return root;
}

// A viewer keeps several connections alive; each holds a worker while it waits for its next
// request, so the pool is sized for many of them (the work per request is a file read).
void sizeForViewers(httplib::Server& server) {
  server.new_task_queue = [] { return new httplib::ThreadPool(kWorkers); };
  server.set_keep_alive_max_count(1000);
  server.set_tcp_nodelay(true);  // headers and body go out as two writes: no Nagle wait
}

// The size of the file a request's path names (a tile or a viewer's file), if it is one.
std::optional<std::uint64_t> servedSize(const fs::path& root, const fs::path& web,
                                        const std::string& path) {
  const auto sizeIn = [](const fs::path& folder,
                         const std::string& relative) -> std::optional<std::uint64_t> {
    if (folder.empty()) return std::nullopt;
    const ResolvedPath resolved = resolveInside(folder, relative);
    std::error_code error;
    const std::uint64_t size = resolved.status == 200 ? fs::file_size(resolved.path, error) : 0;
    if (resolved.status != 200 || error) return std::nullopt;
    return size;
  };
  if (path.starts_with("/tiles/")) return sizeIn(root, path.substr(7));
  for (const std::string_view viewer : {"/cesium/", "/three/", "/assets/"})
    if (path.starts_with(viewer))
      return sizeIn(web, path.substr(1) + (path.ends_with('/') ? "index.html" : ""));
  return std::nullopt;
}

// GET and HEAD only (with the CORS header if asked); the viewers at /cesium/ and /three/ (built
// by `make` into web/dist), the tileset at /tiles/.
void addRoutes(httplib::Server& server, const ServeOptions& o, const fs::path& root,
               const fs::path& web, Caches& caches) {
  server.set_pre_routing_handler([&](const httplib::Request& request, httplib::Response& response) {
    if (request.method != "GET" && request.method != "HEAD") {
      response.status = 405;
      response.set_header("Allow", "GET, HEAD");
      response.set_content("only GET and HEAD\n", "text/plain");
      return httplib::Server::HandlerResponse::Handled;
    }
    if (o.cors) response.set_header("Access-Control-Allow-Origin", "*");
    return httplib::Server::HandlerResponse::Unhandled;
  });
  // cpp-httplib answers a Range it cannot parse ("bytes=10-5") with 416 itself, before any
  // route: the file's size goes with it here, as RFC 9110 §15.5.17 asks.
  const httplib::Server::HandlerWithResponse withSize = [&](const httplib::Request& request,
                                                            httplib::Response& response) {
    if (response.status != 416 || response.has_header("Content-Range"))
      return httplib::Server::HandlerResponse::Unhandled;
    const std::optional<std::uint64_t> size = servedSize(root, web, request.path);
    if (!size) return httplib::Server::HandlerResponse::Unhandled;
    response.set_header("Content-Range", fmt::format("bytes */{}", *size));
    return httplib::Server::HandlerResponse::Handled;
  };
  server.set_error_handler(withSize);
  server.Get("/", [](const httplib::Request&, httplib::Response& response) {
    response.set_redirect("/cesium/");
  });
  server.Get(R"(/tiles/(.*))", [&](const httplib::Request& request, httplib::Response& response) {
    serveFile(root, request.matches[1].str(), request, response, caches);
  });
  server.Get(R"(/((cesium|three|assets)/.*))",
             [&](const httplib::Request& request, httplib::Response& response) {
               std::string relative = request.matches[1].str();
               if (relative.ends_with('/')) relative += "index.html";
               if (web.empty()) {
                 response.status = 404;
                 response.set_content("the viewers are not built: run make\n", "text/plain");
                 return;
               }
               serveFile(web, relative, request, response, caches);
             });
  server.Get(R"(/(cesium|three))",
             [](const httplib::Request& request, httplib::Response& response) {
               response.set_redirect(request.path + "/");
             });
}

// One line per request on stderr, unless -q.
void logRequests(httplib::Server& server, const Global& global) {
  server.set_logger([&global](const httplib::Request& request, const httplib::Response& response) {
    if (global.verbosity >= 0)
      fmt::print(stderr, "{} {} {} {} {}\n", request.remote_addr, request.method, request.path,
                 response.status, response.body.size());
  });
}

// Binds the port (0: a free one) and returns it. cpp-httplib listens with a backlog of 5
// (compiled in): 100 clients connecting at once see their SYNs dropped and retried a second or
// three later. The socket is remembered in `listening` (which outlives the server) and listens
// again with the system's maximum once it is bound (Linux takes a new backlog that way).
Result<int> bindPort(httplib::Server& server, const ServeOptions& o, int& listening) {
  server.set_socket_options([&listening](socket_t socket) {
    int yes = 1;
    ::setsockopt(socket, SOL_SOCKET, SO_REUSEADDR, &yes, sizeof yes);
    listening = socket;
  });
  const int port = o.port == 0 ? server.bind_to_any_port(o.host) : o.port;
  if (o.port != 0 && !server.bind_to_port(o.host, o.port))
    return Error{ErrorKind::kIo, fmt::format("cannot listen on {}:{} (in use?)", o.host, o.port)};
  if (port < 0) return Error{ErrorKind::kIo, fmt::format("cannot listen on {}", o.host)};
  if (listening >= 0) ::listen(listening, SOMAXCONN);
  return port;
}

// Where the tileset and the viewers are, and a warning when other machines can reach them.
void announce(const Global& global, const ServeOptions& o, const fs::path& root,
              const fs::path& web, int port) {
  const std::string base = fmt::format("http://{}:{}", o.host, port);
  say(global, fmt::format("serving {} as {}/tiles/tileset.json", root.string(), base));
  if (web.empty())
    say(global, "the viewers are not built (run make); Ctrl-C stops");
  else
    say(global, fmt::format("open {0}/cesium/ or {0}/three/ to view it; Ctrl-C stops", base));
  std::fflush(stdout);  // a script waiting for the port reads it now, not at exit
  if (o.host != "127.0.0.1" && o.host != "localhost" && o.host != "::1")
    fmt::print(stderr, "lodforge: warning: listening on {}, reachable from other machines\n",
               o.host);
}

// Serves until Ctrl-C, which sets the cancel flag; a watcher thread turns it into a clean stop.
void serveUntilCancelled(httplib::Server& server) {
  std::atomic<bool> done{false};
  std::thread watcher([&] {
    while (!done.load()) {
      if (cancelRequested()) {
        server.stop();
        return;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
    }
  });
  server.listen_after_bind();
  done = true;
  watcher.join();
}

Status runServe(const Global& global, const ServeOptions& o) {
  Result<fs::path> root = tilesetRoot(o.directory);
  if (!root) return root.status();
  const fs::path web = o.web.empty() ? findWebDirectory() : fs::path(o.web);
  httplib::Server server;
  Caches caches;
  if (!server.is_valid()) return Error{ErrorKind::kIo, "cannot start the HTTP server"};
  sizeForViewers(server);
  addRoutes(server, o, *root, web, caches);
  logRequests(server, global);
  int listening = -1;
  Result<int> port = bindPort(server, o, listening);
  if (!port) return port.status();
  announce(global, o, *root, web, *port);
  serveUntilCancelled(server);
  say(global, "stopped");
  return {};
}

}  // namespace

void addServe(CLI::App& app, const Global& global, Run& run) {
  auto o = std::make_shared<ServeOptions>();
  CLI::App* sub = app.add_subcommand("serve", "Serve a tileset and the browser viewers over HTTP");
  sub->add_option("DIR", o->directory, "The tileset directory (lodforge tiles -o DIR)")->required();
  sub->add_option("--port", o->port, "Port (default 8080; 0 picks a free one)")
      ->check(CLI::Range(0, 65535));
  sub->add_option("--host", o->host,
                  "Address to listen on (default 127.0.0.1: this machine only; 0.0.0.0 for all)");
  sub->add_flag("--cors", o->cors, "Add Access-Control-Allow-Origin: * (for viewers elsewhere)");
  sub->add_option("--web", o->web, "The viewers' folder (default: beside the binary)");
  sub->callback([&global, &run, o] { run = [&global, o] { return runServe(global, *o); }; });
}

}  // namespace lodforge::cli
