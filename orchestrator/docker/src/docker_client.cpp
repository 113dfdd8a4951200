#include "swarmbox/docker/docker_client.hpp"

#include <cstdlib>
#include <optional>
#include <utility>

#include "swarmbox/docker/log_demux.hpp"

namespace swarmbox::docker {

// One Engine API request as DockerClient describes it.
struct DockerClient::Call {
  Call(std::string m, std::string p) : method(std::move(m)), path(std::move(p)) {}
  std::string method;
  std::string path;           // without the version prefix, e.g. "/containers/abc/start"
  std::string query;          // "" or "?a=b"
  bool versioned = true;      // prefix the path with /v<api>
  std::string content_type;
  std::string_view body;
  bool creating = false;      // 409 means "already exists"
  bool not_modified_ok = false;  // 304 is success (start/stop of a container already so)
  bool stream = false;        // no overall timeout
  std::chrono::milliseconds extra_timeout{0};
  const BodyChunkFn* on_chunk = nullptr;
  CancelToken* cancel = nullptr;
};

namespace {

std::string Where(const HttpRequest& request, const HttpTransport& transport) {
  return request.method + " " + request.target + " (" + transport.endpoint() + ")";
}

// Re-homes an error from the pure layer at the endpoint it came from.
Error At(const Error& error, std::string where) {
  return Error(error.code(), error.message(), std::move(where));
}

std::string_view WaitConditionName(WaitCondition condition) {
  switch (condition) {
    case WaitCondition::kNotRunning:
      return "not-running";
    case WaitCondition::kNextExit:
      return "next-exit";
    case WaitCondition::kRemoved:
      return "removed";
  }
  return "not-running";
}

}  // namespace

// Sends `call` and parses its body with `parse`; a parse error names the request and the engine.
template <typename Parse>
auto DockerClient::DoParsed(const Call& call, Parse parse) -> decltype(parse(std::string())) {
  auto r = Do(call);
  if (!r) return r.error();
  auto parsed = parse(r->body);
  if (!parsed) {
    return At(parsed.error(), call.method + " " + call.path + " (" + transport_->endpoint() + ")");
  }
  return parsed;
}

std::string DefaultSocketPath() {
  const char* host = std::getenv("DOCKER_HOST");
  if (host != nullptr) {
    std::string_view h(host);
    if (h.rfind("unix://", 0) == 0) return std::string(h.substr(7));
  }
  return "/var/run/docker.sock";
}

Result<std::unique_ptr<DockerClient>> DockerClient::Connect(const DockerClientOptions& options) {
  return Connect(UnixEngine(options.socket_path), options);
}

Result<std::unique_ptr<DockerClient>> DockerClient::Connect(const EngineEndpoint& engine,
                                                            const DockerClientOptions& options) {
  return Connect(std::make_unique<CurlTransport>(engine, options.connect_timeout),
                 options.request_timeout);
}

Result<std::unique_ptr<DockerClient>> DockerClient::Connect(
    std::unique_ptr<HttpTransport> transport, std::chrono::milliseconds request_timeout) {
  std::unique_ptr<DockerClient> client(new DockerClient(std::move(transport), request_timeout));
  if (auto s = client->Negotiate(); !s) return s.error();
  return client;
}

Status DockerClient::Negotiate() {
  std::string engine_api;
  auto ping = Ping();
  if (!ping) return ping.error();
  engine_api = *ping;
  if (engine_api.empty()) {
    auto version = Version();
    if (!version) return version.error();
    engine_api = version->api_version;
  }
  auto engine = ParseApiVersion(engine_api);
  if (!engine) return At(engine.error(), "GET /_ping (" + transport_->endpoint() + ")");
  if (*engine < kMinApiVersion) {
    return Error(ErrorCode::kProtocol,
                 "the engine speaks Docker API " + engine->ToString() + "; SwarmBox needs " +
                     kMinApiVersion.ToString() + " or newer",
                 "GET /_ping (" + transport_->endpoint() + ")");
  }
  version_ = *engine < kMaxApiVersion ? *engine : kMaxApiVersion;
  return Ok{};
}

Result<HttpResponse> DockerClient::Do(const Call& call) {
  HttpRequest request;
  request.method = call.method;
  request.target = (call.versioned ? "/v" + version_.ToString() : std::string()) + call.path +
                   call.query;
  request.content_type = call.content_type;
  request.body = std::string(call.body);
  request.timeout = call.stream ? std::chrono::milliseconds(0) : request_timeout_ + call.extra_timeout;
  static const BodyChunkFn kNoChunks;
  auto response = transport_->Send(request, call.on_chunk != nullptr ? *call.on_chunk : kNoChunks,
                                   call.cancel);
  if (!response) return response.error();
  if (response->success() || (call.not_modified_ok && response->status == 304)) return response;
  return HttpStatusError(response->status, response->body, Where(request, *transport_),
                         call.creating);
}

Status DockerClient::DoStatus(const Call& call) {
  auto r = Do(call);
  if (!r) return r.error();
  return Ok{};
}

Result<std::string> DockerClient::Ping() {
  Call call("GET", "/_ping");
  call.versioned = false;
  auto r = Do(call);
  if (!r) return r.error();
  return r->Header("api-version");
}

Result<EngineVersion> DockerClient::Version() {
  Call call("GET", "/version");
  call.versioned = false;
  return DoParsed(call, [](const std::string& text) { return ParseVersion(text); });
}

// --- images ---------------------------------------------------------------------------------------

namespace {

// What a POST /build response stream said.
struct BuildOutcome {
  std::string image_id;          // aux.ID, "" when the engine did not say
  std::string build_error;       // the first error
  std::string parse_error;       // the first line that is not a build message
  std::string last_stream_line;  // for the message when there is no image id
};

// The state of one POST /build response stream: JSON lines in, progress lines and the outcome out.
class BuildStream {
 public:
  explicit BuildStream(const BuildProgressFn& progress) : progress_(progress) {}

  void Feed(std::string_view chunk) {
    chunk_lines_.Feed(chunk, [this](std::string_view line) { OnLine(line); });
  }

  // Flushes a last line without "\n" from both the response and the build output.
  void Finish() {
    const std::string rest = chunk_lines_.TakeRest();
    if (!rest.empty()) OnLine(rest);
    Emit(output_lines_.TakeRest());
  }

  const BuildOutcome& outcome() const { return outcome_; }

 private:
  void Emit(std::string_view text) {
    if (text.empty()) return;
    outcome_.last_stream_line = std::string(text);
    if (progress_) progress_(text);
  }

  void OnLine(std::string_view line) {
    if (line.empty()) return;
    auto message = ParseBuildLine(line);
    if (!message) {
      if (outcome_.parse_error.empty()) outcome_.parse_error = message.error().message();
      return;
    }
    if (!message->error.empty() && outcome_.build_error.empty()) outcome_.build_error = message->error;
    if (!message->aux_id.empty()) outcome_.image_id = message->aux_id;
    // Output text arrives in pieces ("Step 1/4 : FROM scratch", then "\n"): reassemble lines.
    if (!message->stream.empty()) {
      output_lines_.Feed(message->stream, [this](std::string_view text) { Emit(text); });
    } else if (!message->status.empty()) {
      Emit(message->status);
    }
  }

  const BuildProgressFn& progress_;
  BuildOutcome outcome_;
  LineSplitter chunk_lines_;
  LineSplitter output_lines_;
};

}  // namespace

Result<BuildResult> DockerClient::BuildImage(const BuildRequest& request, const BuildProgressFn& progress,
                                             CancelToken* cancel) {
  const std::string where = "POST /v" + version_.ToString() + "/build (" + transport_->endpoint() + ")";
  if (request.tags.empty()) {
    return Error(ErrorCode::kInvalidArgument, "a build needs at least one tag", where);
  }
  BuildStream stream(progress);
  BodyChunkFn on_chunk = [&stream](std::string_view chunk) { stream.Feed(chunk); };
  Call call("POST", "/build");
  call.query = BuildQuery(request);
  call.content_type = "application/x-tar";
  call.body = request.context_tar;
  call.stream = true;
  call.on_chunk = &on_chunk;
  call.cancel = cancel;
  auto r = Do(call);
  if (!r) return r.error();
  stream.Finish();
  const BuildOutcome& outcome = stream.outcome();
  if (!outcome.build_error.empty()) {
    return Error(ErrorCode::kInvalidArgument, "image build failed: " + outcome.build_error, where);
  }
  if (!outcome.parse_error.empty()) return Error(ErrorCode::kProtocol, outcome.parse_error, where);
  if (!outcome.image_id.empty()) return BuildResult{outcome.image_id};
  // Older engines only say "Successfully built <id>"; ask for the tag instead.
  auto info = InspectImage(request.tags.front());
  if (!info) {
    return Error(ErrorCode::kProtocol,
                 "the build ended without an image id (last output: '" + outcome.last_stream_line +
                     "'): " + info.error().message(),
                 where);
  }
  return BuildResult{info->id};
}

Result<ImageInfo> DockerClient::InspectImage(std::string_view reference) {
  Call call("GET", "/images/" + std::string(reference) + "/json");
  return DoParsed(call, [](const std::string& text) { return ParseImageInspect(text); });
}

Result<std::vector<ImageInfo>> DockerClient::ListImages(const LabelSelector& selector) {
  Call call("GET", "/images/json");
  call.query = "?filters=" + UrlEncode(FiltersJson(selector));
  return DoParsed(call, [](const std::string& text) { return ParseImageList(text); });
}

Status DockerClient::RemoveImage(std::string_view reference, bool force) {
  Call call("DELETE", "/images/" + std::string(reference));
  call.query = force ? "?force=1" : "";
  return DoStatus(call);
}

// --- networks -------------------------------------------------------------------------------------

Result<std::string> DockerClient::CreateNetwork(const NetworkSpec& spec) {
  const std::string body = CreateNetworkBody(spec);
  Call call("POST", "/networks/create");
  call.content_type = "application/json";
  call.body = body;
  call.creating = true;
  return DoParsed(call, [](const std::string& text) { return ParseIdResponse(text); });
}

Result<NetworkInfo> DockerClient::InspectNetwork(std::string_view id) {
  Call call("GET", "/networks/" + std::string(id));
  return DoParsed(call, [](const std::string& text) { return ParseNetwork(text); });
}

Result<std::vector<NetworkInfo>> DockerClient::ListNetworks(const LabelSelector& selector) {
  Call call("GET", "/networks");
  call.query = "?filters=" + UrlEncode(FiltersJson(selector));
  return DoParsed(call, [](const std::string& text) { return ParseNetworkList(text); });
}

Status DockerClient::ConnectNetwork(const EndpointSpec& endpoint, std::string_view container_id) {
  const std::string body = ConnectNetworkBody(endpoint, container_id);
  Call call("POST", "/networks/" + endpoint.network + "/connect");
  call.content_type = "application/json";
  call.body = body;
  return DoStatus(call);
}

Status DockerClient::DisconnectNetwork(std::string_view network_id, std::string_view container_id,
                                       bool force) {
  const std::string body = DisconnectNetworkBody(container_id, force);
  Call call("POST", "/networks/" + std::string(network_id) + "/disconnect");
  call.content_type = "application/json";
  call.body = body;
  return DoStatus(call);
}

Status DockerClient::RemoveNetwork(std::string_view id) {
  Call call("DELETE", "/networks/" + std::string(id));
  return DoStatus(call);
}

// --- containers -----------------------------------------------------------------------------------

Result<std::string> DockerClient::CreateContainer(const ContainerSpec& spec) {
  if (!spec.network_mode.empty() && spec.network_mode.rfind("container:", 0) == 0 &&
      !spec.networks.empty()) {
    return Error(ErrorCode::kInvalidArgument,
                 "a container sharing another's network namespace (" + spec.network_mode +
                     ") cannot join networks of its own",
                 "POST /containers/create");
  }
  const bool all_at_create = !(version_ < ApiVersion{1, 44});
  const std::string body = CreateContainerBody(spec, all_at_create);
  Call call("POST", "/containers/create");
  call.query = spec.name.empty() ? "" : "?name=" + UrlEncode(spec.name);
  call.content_type = "application/json";
  call.body = body;
  call.creating = true;
  auto r = Do(call);
  if (!r) return r.error();
  auto id = ParseIdResponse(r->body);
  if (!id) return At(id.error(), "POST /containers/create (" + transport_->endpoint() + ")");
  if (!all_at_create) {
    for (std::size_t i = 1; i < spec.networks.size(); ++i) {
      if (auto s = ConnectNetwork(spec.networks[i], *id); !s) {
        // Leave nothing half-made behind: the caller sees one failed create.
        (void)RemoveContainer(*id, /*force=*/true, /*remove_volumes=*/true);
        return s.error().Context("connecting the new container to network " +
                                 spec.networks[i].network);
      }
    }
  }
  return id;
}

Result<ContainerInfo> DockerClient::InspectContainer(std::string_view id) {
  Call call("GET", "/containers/" + std::string(id) + "/json");
  return DoParsed(call, [](const std::string& text) { return ParseContainerInspect(text); });
}

Result<std::vector<ContainerSummary>> DockerClient::ListContainers(const LabelSelector& selector,
                                                                   bool all) {
  Call call("GET", "/containers/json");
  call.query = std::string(all ? "?all=1&" : "?") + "filters=" + UrlEncode(FiltersJson(selector));
  return DoParsed(call, [](const std::string& text) { return ParseContainerList(text); });
}

Status DockerClient::StartContainer(std::string_view id) {
  Call call("POST", "/containers/" + std::string(id) + "/start");
  call.not_modified_ok = true;
  return DoStatus(call);
}

Status DockerClient::StopContainer(std::string_view id, int timeout_s) {
  Call call("POST", "/containers/" + std::string(id) + "/stop");
  call.query = "?t=" + std::to_string(timeout_s);
  call.not_modified_ok = true;
  call.extra_timeout = std::chrono::seconds(timeout_s);
  return DoStatus(call);
}

Status DockerClient::RestartContainer(std::string_view id, int timeout_s) {
  Call call("POST", "/containers/" + std::string(id) + "/restart");
  call.query = "?t=" + std::to_string(timeout_s);
  call.extra_timeout = std::chrono::seconds(timeout_s);
  return DoStatus(call);
}

Status DockerClient::KillContainer(std::string_view id, std::string_view signal) {
  Call call("POST", "/containers/" + std::string(id) + "/kill");
  call.query = "?signal=" + UrlEncode(signal);
  return DoStatus(call);
}

Status DockerClient::PauseContainer(std::string_view id) {
  Call call("POST", "/containers/" + std::string(id) + "/pause");
  return DoStatus(call);
}

Status DockerClient::UnpauseContainer(std::string_view id) {
  Call call("POST", "/containers/" + std::string(id) + "/unpause");
  return DoStatus(call);
}

Result<std::int64_t> DockerClient::WaitContainer(std::string_view id, WaitCondition condition,
                                                 CancelToken* cancel) {
  Call call("POST", "/containers/" + std::string(id) + "/wait");
  call.query = "?condition=" + std::string(WaitConditionName(condition));
  call.stream = true;
  call.cancel = cancel;
  return DoParsed(call, [](const std::string& text) { return ParseWaitResponse(text); });
}

Status DockerClient::RemoveContainer(std::string_view id, bool force, bool remove_volumes) {
  std::string query = "?force=" + std::string(force ? "1" : "0") +
                      "&v=" + std::string(remove_volumes ? "1" : "0");
  Call call("DELETE", "/containers/" + std::string(id));
  call.query = query;
  return DoStatus(call);
}

// --- logs and exec --------------------------------------------------------------------------------

Status DockerClient::StreamLines(Call call, bool tty, const LogLineFn& on_line) {
  LogDemuxer demux(tty ? LogDemuxer::Mode::kRaw : LogDemuxer::Mode::kMultiplexed, on_line);
  std::optional<Error> framing_error;
  BodyChunkFn on_chunk = [&](std::string_view chunk) {
    if (auto s = demux.Feed(chunk); !s && !framing_error) framing_error = s.error();
  };
  call.on_chunk = &on_chunk;
  call.stream = true;
  const std::string where =
      call.method + " /v" + version_.ToString() + call.path + " (" + transport_->endpoint() + ")";
  auto r = Do(call);
  // Whatever arrived is delivered, also when the stream was cancelled or broke.
  Status finished = demux.Finish();
  if (!r) return r.error();
  if (framing_error) return At(*framing_error, where);
  if (!finished) return At(finished.error(), where);
  return Ok{};
}

Status DockerClient::FollowLogs(std::string_view id, const LogOptions& options,
                                const LogLineFn& on_line, CancelToken* cancel) {
  auto info = InspectContainer(id);
  if (!info) return info.error();
  if (options.follow && info->state.status == "created") {
    return Error(ErrorCode::kInvalidArgument,
                 "container " + std::string(id) +
                     " was never started: Docker would end the log stream at once; follow its "
                     "logs after StartContainer (no line is lost)",
                 "GET /v" + version_.ToString() + "/containers/" + std::string(id) + "/logs (" +
                     transport_->endpoint() + ")");
  }
  std::string query = "?follow=" + std::string(options.follow ? "1" : "0") +
                      "&stdout=" + std::string(options.stdout ? "1" : "0") +
                      "&stderr=" + std::string(options.stderr ? "1" : "0") +
                      "&timestamps=" + std::string(options.timestamps ? "1" : "0");
  if (options.since_unix_s > 0) query += "&since=" + std::to_string(options.since_unix_s);
  query += "&tail=" + (options.tail ? std::to_string(*options.tail) : std::string("all"));
  Call call("GET", "/containers/" + std::string(id) + "/logs");
  call.query = query;
  call.cancel = cancel;
  return StreamLines(std::move(call), info->tty, on_line);
}

Result<std::string> DockerClient::CreateExec(std::string_view container_id, const ExecSpec& spec) {
  if (spec.cmd.empty()) {
    return Error(ErrorCode::kInvalidArgument, "exec needs a command",
                 "POST /containers/" + std::string(container_id) + "/exec");
  }
  const std::string body = ExecCreateBody(spec);
  Call call("POST", "/containers/" + std::string(container_id) + "/exec");
  call.content_type = "application/json";
  call.body = body;
  return DoParsed(call, [](const std::string& text) { return ParseIdResponse(text); });
}

Status DockerClient::StartExec(std::string_view exec_id, const LogLineFn& on_line,
                               CancelToken* cancel) {
  auto state = InspectExec(exec_id);
  if (!state) return state.error();
  const std::string body = ExecStartBody(state->tty);
  Call call("POST", "/exec/" + std::string(exec_id) + "/start");
  call.content_type = "application/json";
  call.body = body;
  call.cancel = cancel;
  return StreamLines(std::move(call), state->tty, on_line);
}

Result<ExecState> DockerClient::InspectExec(std::string_view exec_id) {
  Call call("GET", "/exec/" + std::string(exec_id) + "/json");
  return DoParsed(call, [](const std::string& text) { return ParseExecInspect(text); });
}

// --- archive --------------------------------------------------------------------------------------

Status DockerClient::PutArchive(std::string_view container_id, std::string_view dest_dir,
                                std::string_view tar) {
  Call call("PUT", "/containers/" + std::string(container_id) + "/archive");
  call.query = "?path=" + UrlEncode(dest_dir);
  call.content_type = "application/x-tar";
  call.body = tar;
  return DoStatus(call);
}

Result<std::string> DockerClient::GetArchive(std::string_view container_id, std::string_view path) {
  Call call("GET", "/containers/" + std::string(container_id) + "/archive");
  call.query = "?path=" + UrlEncode(path);
  auto r = Do(call);
  if (!r) return r.error();
  return std::move(r->body);
}

// --- events ---------------------------------------------------------------------------------------

Status DockerClient::StreamEvents(const EventFilter& filter, const EventFn& on_event,
                                  CancelToken* cancel) {
  std::map<std::string, std::vector<std::string>> extra;
  if (!filter.types.empty()) extra["type"] = filter.types;
  if (!filter.actions.empty()) extra["event"] = filter.actions;
  std::string query = "?filters=" + UrlEncode(FiltersJson(filter.labels, extra));
  if (filter.since_unix_s > 0) query += "&since=" + std::to_string(filter.since_unix_s);
  LineSplitter splitter;
  std::optional<Error> parse_error;
  auto on_line = [&](std::string_view line) {
    if (line.empty()) return;
    auto event = ParseEvent(line);
    if (!event) {
      if (!parse_error) parse_error = event.error();
      return;
    }
    if (on_event) on_event(*event);
  };
  BodyChunkFn on_chunk = [&](std::string_view chunk) { splitter.Feed(chunk, on_line); };
  Call call("GET", "/events");
  call.query = query;
  call.stream = true;
  call.on_chunk = &on_chunk;
  call.cancel = cancel;
  auto r = Do(call);
  if (!r) return r.error();
  if (parse_error) {
    return At(*parse_error, "GET /v" + version_.ToString() + "/events (" + transport_->endpoint() + ")");
  }
  return Ok{};
}

}  // namespace swarmbox::docker
