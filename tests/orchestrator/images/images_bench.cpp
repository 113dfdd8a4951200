// swarmbox-bench images: the figures of the registry-free image path.
//
//   swarmbox-bench images [--physics PATH] [--agent PATH] [--runs N] [--no-docker] [--quick]
//
// Per image (the e2e probe, the fault tools, and physics/agent when their binaries are given):
// context pack time and size; with an engine also the build time (first time) or the cached
// check, and the image size. Then create-to-first-log-line of the probe image over N runs: the
// time from POST /containers/create to the first streamed log line, as the runner sees it.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <string>
#include <thread>
#include <vector>

#include "bench.hpp"
#include "probe_image.hpp"
#include "swarmbox/docker/docker_client.hpp"
#include "swarmbox/docker/remove_labelled.hpp"
#include "swarmbox/images/ensure_image.hpp"
#include "swarmbox/images/image_context.hpp"
#include "swarmbox/images/standard_images.hpp"

namespace swarmbox {
namespace {

using Clock = std::chrono::steady_clock;

double MsSince(Clock::time_point t) {
  return std::chrono::duration<double, std::milli>(Clock::now() - t).count();
}

int RunImagesBench(const bench::Args& args) {
  std::vector<images::ImageSpec> specs = {testing::ProbeImageSpec()};
  if (auto faults = images::FaultToolsImage(); faults) {
    specs.push_back(*faults);
  } else {
    std::printf("suite=images scenario=pack image=swarmbox/faults error=%s\n",
                faults.error().ToString().c_str());
  }
  if (auto p = args.Get("physics", ""); !p.empty()) specs.push_back(images::PhysicsImage(p));
  if (auto a = args.Get("agent", ""); !a.empty()) specs.push_back(images::AgentImage(a));

  int failures = 0;
  for (const auto& spec : specs) {
    const auto t = Clock::now();
    auto ctx = images::PackContext(spec);
    if (!ctx) {
      std::printf("suite=images scenario=pack image=%s error=\"%s\"\n", spec.repository.c_str(),
                  ctx.error().ToString().c_str());
      ++failures;
      continue;
    }
    std::printf("suite=images scenario=pack image=%s files=%zu payload_bytes=%zu context_bytes=%zu pack_ms=%.1f\n",
                spec.repository.c_str(), ctx->image_paths.size(), ctx->payload_bytes, ctx->tar.size(),
                MsSince(t));
  }
  if (args.options.count("no-docker") != 0) return failures == 0 ? 0 : 1;

  auto api = docker::DockerClient::Connect({.socket_path = docker::DefaultSocketPath(),
                                            .connect_timeout = std::chrono::seconds(5),
                                            .request_timeout = std::chrono::seconds(60)});
  if (!api) {
    std::printf("suite=images scenario=engine error=\"%s\"\n", api.error().ToString().c_str());
    return 1;
  }
  std::string probe_tag;
  for (const auto& spec : specs) {
    auto r = images::EnsureImage(**api, spec, nullptr, nullptr);
    if (!r) {
      std::printf("suite=images scenario=ensure image=%s error=\"%s\"\n", spec.repository.c_str(),
                  r.error().ToString().c_str());
      ++failures;
      continue;
    }
    if (spec.repository == "swarmbox/e2e-probe") probe_tag = r->tag;
    std::printf("suite=images scenario=ensure image=%s tag=%s built=%d image_bytes=%lld build_ms=%.1f pack_ms=%.1f\n",
                spec.repository.c_str(), r->tag.c_str(), r->built ? 1 : 0,
                static_cast<long long>(r->image_size_bytes), r->build_s * 1e3, r->pack_s * 1e3);
  }
  if (probe_tag.empty()) return 1;

  const long runs = args.quick ? 2 : args.GetInt("runs", 5);
  const std::string run_id = "bench-" + std::to_string(getpid());
  std::vector<double> first_line_ms;
  for (long i = 0; i < runs; ++i) {
    docker::ContainerSpec c;
    c.image = probe_tag;
    c.cmd = {"serve", "0"};
    c.user = "1000:1000";
    c.labels = docker::SwarmboxLabels(run_id, "bench", "probe");
    const auto t = Clock::now();
    auto id = (*api)->CreateContainer(c);
    if (!id) {
      std::printf("suite=images scenario=first_line error=\"%s\"\n", id.error().ToString().c_str());
      ++failures;
      break;
    }
    const double create_ms = MsSince(t);
    if (auto s = (*api)->StartContainer(*id); !s) {
      std::printf("suite=images scenario=first_line error=\"%s\"\n", s.error().ToString().c_str());
      ++failures;
      break;
    }
    const double start_ms = MsSince(t);
    docker::CancelToken got_line;
    double line_ms = -1;
    auto s = (*api)->FollowLogs(*id, {}, [&](const docker::LogLine&) {
      if (line_ms < 0) line_ms = MsSince(t);
      got_line.Cancel();
    }, &got_line);
    (void)s;  // kCancelled on purpose once the first line is in
    first_line_ms.push_back(line_ms);
    std::printf("suite=images scenario=first_line run=%ld create_ms=%.1f start_returned_ms=%.1f first_line_ms=%.1f\n",
                i, create_ms, start_ms, line_ms);
    (void)(*api)->RemoveContainer(*id, true, true);
  }
  docker::LabelSelector sel;
  sel.equals = {{std::string(docker::kLabelRun), run_id}};
  (void)docker::RemoveLabelled(**api, sel, false);
  if (!first_line_ms.empty()) {
    std::sort(first_line_ms.begin(), first_line_ms.end());
    std::printf("suite=images scenario=first_line_summary runs=%zu min_ms=%.1f p50_ms=%.1f max_ms=%.1f\n",
                first_line_ms.size(), first_line_ms.front(), first_line_ms[first_line_ms.size() / 2],
                first_line_ms.back());
  }
  return failures == 0 ? 0 : 1;
}

}  // namespace
}  // namespace swarmbox

SWARMBOX_BENCH_SUITE(images, "registry-free images: pack/build time, sizes, create-to-first-log-line",
                     swarmbox::RunImagesBench);
