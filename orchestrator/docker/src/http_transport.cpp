#include "swarmbox/docker/http_transport.hpp"

#include <curl/curl.h>

#include <algorithm>
#include <cctype>
#include <cstdio>
#include <mutex>

namespace swarmbox::docker {
namespace {

void GlobalInitOnce() {
  static std::once_flag once;
  std::call_once(once, [] { curl_global_init(CURL_GLOBAL_DEFAULT); });
}

std::string Lower(std::string_view s) {
  std::string out(s);
  std::transform(out.begin(), out.end(), out.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return out;
}

std::string_view Trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t' || s.back() == '\r' || s.back() == '\n')) {
    s.remove_suffix(1);
  }
  return s;
}

// State shared with libcurl's callbacks for one exchange.
struct Exchange {
  CURL* easy = nullptr;
  const BodyChunkFn* on_chunk = nullptr;
  HttpResponse response;
  bool status_known = false;
  std::string_view upload;  // remaining request body
};

size_t OnHeader(char* data, size_t size, size_t count, void* user) {
  auto* ex = static_cast<Exchange*>(user);
  const size_t n = size * count;
  std::string_view line(data, n);
  if (line.rfind("HTTP/", 0) == 0) {
    // A new status line (also after "100 Continue"): start over.
    ex->response.headers.clear();
    return n;
  }
  const size_t colon = line.find(':');
  if (colon != std::string_view::npos) {
    ex->response.headers[Lower(Trim(line.substr(0, colon)))] = std::string(Trim(line.substr(colon + 1)));
  }
  return n;
}

size_t OnBody(char* data, size_t size, size_t count, void* user) {
  auto* ex = static_cast<Exchange*>(user);
  const size_t n = size * count;
  if (!ex->status_known) {
    long code = 0;
    curl_easy_getinfo(ex->easy, CURLINFO_RESPONSE_CODE, &code);
    ex->response.status = static_cast<int>(code);
    ex->status_known = true;
  }
  if (ex->on_chunk != nullptr && *ex->on_chunk && ex->response.success()) {
    (*ex->on_chunk)(std::string_view(data, n));
  } else {
    ex->response.body.append(data, n);
  }
  return n;
}

size_t OnUpload(char* buffer, size_t size, size_t count, void* user) {
  auto* ex = static_cast<Exchange*>(user);
  const size_t n = std::min(size * count, ex->upload.size());
  std::copy_n(ex->upload.data(), n, buffer);
  ex->upload.remove_prefix(n);
  return n;
}

ErrorCode MapCurlCode(CURLcode code) {
  switch (code) {
    case CURLE_COULDNT_CONNECT:
    case CURLE_COULDNT_RESOLVE_HOST:
      return ErrorCode::kUnavailable;
    case CURLE_OPERATION_TIMEDOUT:
      return ErrorCode::kTimeout;
    case CURLE_ABORTED_BY_CALLBACK:
      return ErrorCode::kCancelled;
    case CURLE_OUT_OF_MEMORY:
    case CURLE_BAD_FUNCTION_ARGUMENT:
      return ErrorCode::kInternal;
    default:
      return ErrorCode::kIo;
  }
}

// The request's headers; an empty Expect: stops libcurl from waiting a second for "100 Continue"
// on large bodies. The caller frees the list (curl_slist_free_all).
curl_slist* RequestHeaders(const HttpRequest& request) {
  curl_slist* headers = nullptr;
  headers = curl_slist_append(headers, "Expect:");
  if (!request.content_type.empty()) {
    headers = curl_slist_append(headers, ("Content-Type: " + request.content_type).c_str());
  }
  for (const auto& [name, value] : request.headers) {
    headers = curl_slist_append(headers, (name + ": " + value).c_str());
  }
  return headers;
}

// How to reach the engine: its unix socket, or TCP with TLS as the docker CLI does it.
void SetEngineOptions(CURL* e, const EngineEndpoint& engine) {
  if (engine.kind == EngineEndpoint::Kind::kUnix) {
    curl_easy_setopt(e, CURLOPT_UNIX_SOCKET_PATH, engine.socket_path.c_str());
  } else if (engine.tls) {
    // As the docker CLI: the engine's certificate against ca.pem (or the system's CAs), the
    // client's own certificate when there is one; DOCKER_TLS alone checks nothing.
    if (!engine.ca_file.empty()) curl_easy_setopt(e, CURLOPT_CAINFO, engine.ca_file.c_str());
    if (!engine.cert_file.empty()) {
      curl_easy_setopt(e, CURLOPT_SSLCERT, engine.cert_file.c_str());
      curl_easy_setopt(e, CURLOPT_SSLKEY, engine.key_file.c_str());
    }
    curl_easy_setopt(e, CURLOPT_SSL_VERIFYPEER, engine.tls_verify ? 1L : 0L);
    curl_easy_setopt(e, CURLOPT_SSL_VERIFYHOST, engine.tls_verify ? 2L : 0L);
  }
}

// The URL, headers, error buffer and the callbacks that fill ex->response.
void SetTransferOptions(CURL* e, const std::string& url, curl_slist* headers, char* error_buffer, Exchange* ex) {
  curl_easy_setopt(e, CURLOPT_URL, url.c_str());
  curl_easy_setopt(e, CURLOPT_HTTPHEADER, headers);
  curl_easy_setopt(e, CURLOPT_ERRORBUFFER, error_buffer);
  curl_easy_setopt(e, CURLOPT_NOSIGNAL, 1L);
  curl_easy_setopt(e, CURLOPT_HEADERFUNCTION, &OnHeader);
  curl_easy_setopt(e, CURLOPT_HEADERDATA, ex);
  curl_easy_setopt(e, CURLOPT_WRITEFUNCTION, &OnBody);
  curl_easy_setopt(e, CURLOPT_WRITEDATA, ex);
}

// The method, and the body read from ex->upload for POST, PUT and other methods with a body.
void SetMethodOptions(CURL* e, const HttpRequest& request, Exchange* ex) {
  if (request.method == "GET") {
    curl_easy_setopt(e, CURLOPT_HTTPGET, 1L);
  } else if (request.method == "HEAD") {
    curl_easy_setopt(e, CURLOPT_NOBODY, 1L);
  } else if (request.method != "POST" && request.method != "PUT" && request.body.empty()) {
    curl_easy_setopt(e, CURLOPT_CUSTOMREQUEST, request.method.c_str());  // DELETE
  } else {
    if (request.method == "POST") {
      curl_easy_setopt(e, CURLOPT_POST, 1L);
    } else {
      curl_easy_setopt(e, CURLOPT_UPLOAD, 1L);
      curl_easy_setopt(e, CURLOPT_CUSTOMREQUEST, request.method.c_str());
    }
    curl_easy_setopt(e, CURLOPT_READFUNCTION, &OnUpload);
    curl_easy_setopt(e, CURLOPT_READDATA, ex);
    if (request.method == "POST") {
      curl_easy_setopt(e, CURLOPT_POSTFIELDSIZE_LARGE,
                       static_cast<curl_off_t>(request.body.size()));
    } else {
      curl_easy_setopt(e, CURLOPT_INFILESIZE_LARGE, static_cast<curl_off_t>(request.body.size()));
    }
  }
}

// How a transfer ended: libcurl's result (CURLE_RECV_ERROR when the multi interface failed, its
// message in the error buffer), or cancelled.
struct TransferEnd {
  CURLcode result = CURLE_OK;
  bool cancelled = false;
};

// Drives the transfer until it is done, fails or `cancel` fires (which wakes the poll).
TransferEnd Perform(CURLM* multi, CancelToken* cancel, char (&error_buffer)[CURL_ERROR_SIZE]) {
  std::uint64_t waker = 0;
  if (cancel != nullptr) waker = cancel->Register([multi] { curl_multi_wakeup(multi); });
  TransferEnd end;
  bool done = false;
  while (!done) {
    int running = 0;
    CURLMcode mc = curl_multi_perform(multi, &running);
    if (mc != CURLM_OK) {
      end.result = CURLE_RECV_ERROR;
      std::snprintf(error_buffer, sizeof(error_buffer), "curl_multi_perform: %s",
                    curl_multi_strerror(mc));
      break;
    }
    int queued = 0;
    while (CURLMsg* msg = curl_multi_info_read(multi, &queued)) {
      if (msg->msg == CURLMSG_DONE) {
        end.result = msg->data.result;
        done = true;
      }
    }
    if (done) break;
    if (cancel != nullptr && cancel->cancelled()) {
      end.cancelled = true;
      break;
    }
    mc = curl_multi_poll(multi, nullptr, 0, 1000, nullptr);
    if (mc != CURLM_OK) {
      end.result = CURLE_RECV_ERROR;
      std::snprintf(error_buffer, sizeof(error_buffer), "curl_multi_poll: %s",
                    curl_multi_strerror(mc));
      break;
    }
  }
  if (cancel != nullptr) cancel->Unregister(waker);
  return end;
}

// The error of a failed transfer: libcurl's message, and for a refused connection where no engine
// answers.
Error TransferError(CURLcode result, const char* error_buffer, const EngineEndpoint& engine,
                    const std::string& where) {
  std::string detail = error_buffer[0] != '\0' ? error_buffer : curl_easy_strerror(result);
  if (result == CURLE_COULDNT_CONNECT) {
    const std::string at = engine.kind == EngineEndpoint::Kind::kUnix ? engine.socket_path : engine.ToString();
    detail = "no Docker engine answers at " + at + " (" + detail + ")";
  }
  return Error(MapCurlCode(result), detail, where);
}

// Takes the status from libcurl when no status line was seen, then frees both handles.
void EndExchange(CURLM* multi, Exchange& ex) {
  if (!ex.status_known) {
    long code = 0;
    curl_easy_getinfo(ex.easy, CURLINFO_RESPONSE_CODE, &code);
    ex.response.status = static_cast<int>(code);
  }
  curl_multi_remove_handle(multi, ex.easy);
  curl_easy_cleanup(ex.easy);
  curl_multi_cleanup(multi);
}

}  // namespace

std::string HttpResponse::Header(std::string_view name) const {
  auto it = headers.find(std::string(name));
  return it == headers.end() ? std::string() : it->second;
}

CurlTransport::CurlTransport(EngineEndpoint engine, std::chrono::milliseconds connect_timeout)
    : engine_(std::move(engine)), base_url_(engine_.BaseUrl()), connect_timeout_(connect_timeout) {
  GlobalInitOnce();
}

Result<HttpResponse> CurlTransport::Send(const HttpRequest& request,
                                               const BodyChunkFn& on_chunk, CancelToken* cancel) {
  const std::string where = request.method + " " + request.target + " (" + endpoint() + ")";
  if (cancel != nullptr && cancel->cancelled()) {
    return Error(ErrorCode::kCancelled, "cancelled before sending", where);
  }
  Exchange ex;
  ex.on_chunk = &on_chunk;
  ex.upload = request.body;
  ex.easy = curl_easy_init();
  CURLM* multi = curl_multi_init();
  if (ex.easy == nullptr || multi == nullptr) {
    if (ex.easy != nullptr) curl_easy_cleanup(ex.easy);
    if (multi != nullptr) curl_multi_cleanup(multi);
    return Error(ErrorCode::kInternal, "libcurl could not allocate a handle", where);
  }
  const std::string url = base_url_ + request.target;
  char error_buffer[CURL_ERROR_SIZE] = {0};
  curl_slist* headers = RequestHeaders(request);
  CURL* e = ex.easy;
  SetEngineOptions(e, engine_);
  SetTransferOptions(e, url, headers, error_buffer, &ex);
  curl_easy_setopt(e, CURLOPT_CONNECTTIMEOUT_MS, static_cast<long>(connect_timeout_.count()));
  curl_easy_setopt(e, CURLOPT_TIMEOUT_MS, static_cast<long>(request.timeout.count()));
  curl_easy_setopt(e, CURLOPT_BUFFERSIZE, 64L * 1024L);
  SetMethodOptions(e, request, &ex);
  curl_multi_add_handle(multi, e);
  const TransferEnd end = Perform(multi, cancel, error_buffer);
  EndExchange(multi, ex);
  curl_slist_free_all(headers);
  if (end.cancelled) return Error(ErrorCode::kCancelled, "cancelled", where);
  if (end.result != CURLE_OK) return TransferError(end.result, error_buffer, engine_, where);
  return std::move(ex.response);
}

}  // namespace swarmbox::docker
