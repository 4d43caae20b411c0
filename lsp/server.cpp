#include "lsp/server.h"

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <deque>
#include <functional>
#include <iostream>
#include <map>
#include <set>
#include <thread>

#include "lsp/features.h"
#include "lsp/transport.h"

namespace sdfc::lsp {
namespace {

class Server {
 public:
  explicit Server(std::ostream& out) : writer_(out) {}
  explicit Server(int out_fd) : writer_(out_fd) {}

  int run(std::istream& in) {
    diagnostics_thread_ = std::thread([this] { diagnosticsLoop(); });
    while (!exit_requested_) {
      std::optional<Frame> frame = readFrame(in);
      if (!frame) break;
      if (frame->malformed) {
        sendError(nullptr, kParseError, "a message needs a Content-Length header");
        continue;
      }
      if (frame->too_large) {
        sendError(nullptr, kParseError,
                  "a message over the " + std::to_string(kMaxBodyBytes >> 20) + " MiB limit was skipped");
        continue;
      }
      handle(frame->body);
    }
    {
      std::lock_guard<std::mutex> lock(diag_mutex_);
      stopping_ = true;
    }
    diag_cv_.notify_all();
    diagnostics_thread_.join();
    // Answer what is queued, then stop the workers.
    {
      std::lock_guard<std::mutex> lock(workers_mutex_);
      workers_stop_ = true;
    }
    workers_cv_.notify_all();
    for (std::thread& t : workers_) t.join();
    return shutdown_requested_ ? 0 : 1;
  }

 private:
  Writer writer_;
  DocumentStore documents_;
  bool utf8_ = false;  // position encoding agreed at initialize
  std::atomic<bool> initialized_{false}, shutdown_requested_{false}, exit_requested_{false};

  // Requests are answered by a pool that grows, up to kMaxWorkers threads,
  // whenever none is idle: a request waits only behind that many slow ones.
  static constexpr size_t kMaxWorkers = 8;
  std::mutex workers_mutex_;
  std::condition_variable workers_cv_;
  std::vector<std::thread> workers_;
  std::deque<std::function<void()>> tasks_;
  size_t idle_workers_ = 0;
  bool workers_stop_ = false;

  void enqueue(std::function<void()> task) {
    std::lock_guard<std::mutex> lock(workers_mutex_);
    tasks_.push_back(std::move(task));
    if (idle_workers_ == 0 && workers_.size() < kMaxWorkers)
      workers_.emplace_back([this] { workerLoop(); });
    else
      workers_cv_.notify_one();
  }

  void workerLoop() {
    std::unique_lock<std::mutex> lock(workers_mutex_);
    while (true) {
      ++idle_workers_;
      workers_cv_.wait(lock, [this] { return workers_stop_ || !tasks_.empty(); });
      --idle_workers_;
      if (tasks_.empty()) return;  // stopping, and nothing left to answer
      std::function<void()> task = std::move(tasks_.front());
      tasks_.pop_front();
      lock.unlock();
      task();
      lock.lock();
    }
  }

  std::mutex cancel_mutex_;
  std::set<std::string> in_flight_;  // request ids being answered, as JSON text
  std::set<std::string> cancelled_;  // of those, the ones the client cancelled

  // The newest analysis per document, shared by requests and diagnostics.
  std::mutex cache_mutex_;
  std::map<std::string, std::shared_ptr<const Analysis>> cache_;

  // Documents waiting for diagnostics: only the newest version of each.
  std::thread diagnostics_thread_;
  std::mutex diag_mutex_;
  std::condition_variable diag_cv_;
  std::map<std::string, std::shared_ptr<const Document>> pending_;
  std::set<std::string> closed_;
  bool stopping_ = false;

  // ---- messages -------------------------------------------------------------

  void send(const json& message) { writer_.send(message.dump(-1, ' ', false, json::error_handler_t::replace)); }
  void sendResult(const json& id, const json& result) {
    send({{"jsonrpc", "2.0"}, {"id", id}, {"result", result}});
  }
  void sendError(const json& id, int code, const std::string& message) {
    send({{"jsonrpc", "2.0"}, {"id", id}, {"error", {{"code", code}, {"message", message}}}});
  }
  void notify(const std::string& method, const json& params) {
    send({{"jsonrpc", "2.0"}, {"method", method}, {"params", params}});
  }

  void handle(const std::string& body) {
    json message;
    try {
      message = json::parse(body);
    } catch (const json::exception& e) {
      sendError(nullptr, kParseError, std::string("the message is not JSON: ") + e.what());
      return;
    }
    const bool has_id = message.is_object() && message.contains("id") &&
                        (message["id"].is_number_integer() || message["id"].is_string());
    const json id = has_id ? message["id"] : json(nullptr);
    if (!message.is_object() || !message.contains("method") || !message["method"].is_string()) {
      // A response to a request we never sent is dropped; anything else is invalid.
      if (message.is_object() && (message.contains("result") || message.contains("error"))) return;
      sendError(id, kInvalidRequest, "a request needs a string 'method'");
      return;
    }
    if (message.contains("id") && !has_id) {
      sendError(nullptr, kInvalidRequest, "'id' must be a number or a string");
      return;
    }
    const std::string method = message["method"];
    const json params = message.contains("params") ? message["params"] : json::object();
    try {
      if (!has_id) return notification(method, params);
      request(id, method, params);
    } catch (const RpcError& e) {
      if (has_id) sendError(id, e.code, e.what());
    } catch (const std::exception& e) {
      if (has_id) sendError(id, kInvalidParams, e.what());
      else notify("window/logMessage", {{"type", 1}, {"message", method + ": " + e.what()}});
    }
  }

  void notification(const std::string& method, const json& params) {
    if (method == "exit") {
      exit_requested_ = true;
      return;
    }
    if (method == "$/cancelRequest") {
      std::lock_guard<std::mutex> lock(cancel_mutex_);
      // A cancel for a request already answered (or never sent) is dropped.
      const std::string id = params.at("id").dump();
      if (in_flight_.count(id)) cancelled_.insert(id);
      return;
    }
    if (!initialized_) return;  // notifications before initialize are dropped
    if (method == "textDocument/didOpen") {
      const json& doc = params.at("textDocument");
      documents_.open(doc.at("uri"), doc.value("version", 0), doc.at("text"));
      schedule(doc.at("uri"));
    } else if (method == "textDocument/didChange") {
      const json& doc = params.at("textDocument");
      if (!documents_.change(doc.at("uri"), doc.value("version", 0), params.at("contentChanges"), utf8_))
        throw std::invalid_argument("didChange for a document that is not open");
      schedule(doc.at("uri"));
    } else if (method == "textDocument/didClose") {
      const std::string uri = params.at("textDocument").at("uri");
      documents_.close(uri);
      {
        std::lock_guard<std::mutex> lock(cache_mutex_);
        cache_.erase(uri);
      }
      {
        std::lock_guard<std::mutex> lock(diag_mutex_);
        pending_.erase(uri);
        closed_.insert(uri);
      }
      diag_cv_.notify_one();
    }
    // initialized, didSave, setTrace, didChangeConfiguration...: nothing to do.
  }

  void request(const json& id, const std::string& method, const json& params) {
    if (method == "initialize") {
      if (initialized_) throw RpcError(kInvalidRequest, "initialize was already received");
      initialize(id, params);
      return;
    }
    if (!initialized_) throw RpcError(kServerNotInitialized, "the first request must be initialize");
    if (shutdown_requested_) throw RpcError(kInvalidRequest, "the server is shutting down");
    if (method == "shutdown") {
      shutdown_requested_ = true;
      sendResult(id, nullptr);
      return;
    }
    // The document as it is now (later edits do not change this request's answer).
    std::shared_ptr<const Document> doc;
    if (params.is_object() && params.contains("textDocument")) {
      const json& uri = params["textDocument"].at("uri");
      if (!uri.is_string()) throw RpcError(kInvalidParams, "textDocument.uri must be a string");
      doc = documents_.get(uri);
      if (!doc) throw RpcError(kInvalidParams, "the document " + uri.get<std::string>() + " is not open");
    }
    if (!known(method)) throw RpcError(kMethodNotFound, "unknown method '" + method + "'");
    if (!doc) throw RpcError(kInvalidParams, method + " needs params.textDocument");
    {
      std::lock_guard<std::mutex> lock(cancel_mutex_);
      in_flight_.insert(id.dump());
    }
    enqueue([this, id, method, params, doc] {
      answer(id, method, params, doc);
      std::lock_guard<std::mutex> lock(cancel_mutex_);
      in_flight_.erase(id.dump());
      cancelled_.erase(id.dump());
    });
  }

  static bool known(const std::string& m) {
    static const std::set<std::string> methods = {
        "textDocument/hover", "textDocument/definition", "textDocument/references",
        "textDocument/rename", "textDocument/prepareRename", "textDocument/completion",
        "textDocument/signatureHelp", "textDocument/documentSymbol", "textDocument/formatting",
        "textDocument/documentHighlight"};
    return methods.count(m) > 0;
  }

  bool takeCancelled(const json& id) {
    std::lock_guard<std::mutex> lock(cancel_mutex_);
    return cancelled_.erase(id.dump()) > 0;
  }

  // On a worker thread.
  void answer(const json& id, const std::string& method, const json& params,
              std::shared_ptr<const Document> doc) {
    try {
      if (takeCancelled(id)) throw RpcError(kRequestCancelled, "cancelled");
      std::shared_ptr<const Analysis> a = analysisOf(*doc);
      if (takeCancelled(id)) throw RpcError(kRequestCancelled, "cancelled");
      auto offset = [&] { return a->lines.offsetOf(params.at("position")); };
      json result;
      if (method == "textDocument/hover") result = hover(*a, offset());
      else if (method == "textDocument/definition") result = definition(*a, offset());
      else if (method == "textDocument/references")
        result = references(*a, offset(),
                            params.value("/context/includeDeclaration"_json_pointer, true));
      else if (method == "textDocument/documentHighlight") result = documentHighlight(*a, offset());
      else if (method == "textDocument/prepareRename") result = prepareRename(*a, offset());
      else if (method == "textDocument/rename") {
        if (!params.contains("newName") || !params["newName"].is_string())
          throw RpcError(kInvalidParams, "rename needs a string 'newName'");
        result = rename(*a, offset(), params["newName"]);
      } else if (method == "textDocument/completion") result = completion(*a, offset());
      else if (method == "textDocument/signatureHelp") result = signatureHelp(*a, offset());
      else if (method == "textDocument/documentSymbol") result = documentSymbols(*a);
      else if (method == "textDocument/formatting") result = formatting(*a);
      sendResult(id, result);
    } catch (const RpcError& e) {
      sendError(id, e.code, e.what());
    } catch (const json::exception& e) {
      sendError(id, kInvalidParams, e.what());
    } catch (const std::invalid_argument& e) {
      sendError(id, kInvalidParams, e.what());
    } catch (const std::exception& e) {
      sendError(id, kInternalError, e.what());
    }
  }

  void initialize(const json& id, const json& params) {
    const json encodings = params.value("/capabilities/general/positionEncodings"_json_pointer, json::array());
    for (const json& e : encodings)
      if (e == "utf-8") utf8_ = true;
    const json capabilities = {
        {"positionEncoding", utf8_ ? "utf-8" : "utf-16"},
        {"textDocumentSync", {{"openClose", true}, {"change", 2}}},  // 2: incremental
        {"hoverProvider", true},
        {"definitionProvider", true},
        {"referencesProvider", true},
        {"documentHighlightProvider", true},
        {"renameProvider", {{"prepareProvider", true}}},
        {"completionProvider", {{"triggerCharacters", {"(", ",", ":", " "}}}},
        {"signatureHelpProvider", {{"triggerCharacters", {"(", ","}}, {"retriggerCharacters", {":"}}}},
        {"documentSymbolProvider", true},
        {"documentFormattingProvider", true},
    };
    initialized_ = true;
    sendResult(id, {{"capabilities", capabilities}, {"serverInfo", {{"name", "sdfc"}, {"version", "0.1.0"}}}});
  }

  // ---- analyses and diagnostics ---------------------------------------------

  std::shared_ptr<const Analysis> analysisOf(const Document& doc) {
    if (const std::string why = documentTooLarge(doc.text.size()); !why.empty()) throw RpcError(kRequestFailed, why);
    {
      std::lock_guard<std::mutex> lock(cache_mutex_);
      auto it = cache_.find(doc.uri);
      if (it != cache_.end() && it->second->version == doc.version && it->second->text() == doc.text)
        return it->second;
    }
    std::shared_ptr<const Analysis> a = analyzeDocument(doc, utf8_);
    std::lock_guard<std::mutex> lock(cache_mutex_);
    auto it = cache_.find(doc.uri);
    if (documents_.get(doc.uri) && (it == cache_.end() || it->second->version <= doc.version)) cache_[doc.uri] = a;
    return a;
  }

  void schedule(const std::string& uri) {
    std::shared_ptr<const Document> doc = documents_.get(uri);
    if (!doc) return;
    {
      std::lock_guard<std::mutex> lock(diag_mutex_);
      pending_[uri] = doc;
      closed_.erase(uri);
    }
    diag_cv_.notify_one();
  }

  void diagnosticsLoop() {
    std::unique_lock<std::mutex> lock(diag_mutex_);
    while (true) {
      diag_cv_.wait(lock, [this] { return stopping_ || !pending_.empty() || !closed_.empty(); });
      if (stopping_) return;
      std::set<std::string> closed = std::move(closed_);
      closed_.clear();
      std::map<std::string, std::shared_ptr<const Document>> batch = std::move(pending_);
      pending_.clear();
      lock.unlock();
      for (const std::string& uri : closed)
        notify("textDocument/publishDiagnostics", {{"uri", uri}, {"diagnostics", json::array()}});
      for (const auto& [uri, doc] : batch) {
        try {
          // A newer version arrived meanwhile: skip this one, the next batch has it.
          std::shared_ptr<const Document> now = documents_.get(uri);
          if (!now || now->version != doc->version || now->text != doc->text) continue;
          if (const std::string why = documentTooLarge(doc->text.size()); !why.empty()) {
            const json start = {{"line", 0}, {"character", 0}};
            notify("textDocument/publishDiagnostics",
                   {{"uri", uri}, {"version", doc->version},
                    {"diagnostics", json::array({{{"range", {{"start", start}, {"end", start}}},
                                                  {"severity", 1}, {"source", "sdfc"}, {"message", why}}})}});
            continue;
          }
          notify("textDocument/publishDiagnostics", publishDiagnostics(*analysisOf(*doc)));
        } catch (const std::exception& e) {
          notify("window/logMessage", {{"type", 1}, {"message", std::string("diagnostics: ") + e.what()}});
        }
      }
      lock.lock();
    }
  }
};

}  // namespace

int runServer(std::istream& in, std::ostream& out) {
  Server server(out);
  return server.run(in);
}

int runServer(std::istream& in, int out_fd) {
  Server server(out_fd);
  return server.run(in);
}

int runStdioServer() {
  // Nothing else may write to stdout: it carries the protocol.
  // std::cin is tied to std::cout: a read would flush cout from the reading
  // thread, outside the writer's lock, so frames go out by write(2) instead.
  std::ios::sync_with_stdio(false);
  std::cin.tie(nullptr);
  return runServer(std::cin, 1);
}

}  // namespace sdfc::lsp
