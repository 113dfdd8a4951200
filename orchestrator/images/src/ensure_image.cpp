#include "swarmbox/images/ensure_image.hpp"

#include <chrono>

#include "swarmbox/images/image_context.hpp"

namespace swarmbox::images {
namespace {

double SecondsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

}  // namespace

namespace {

// The cached tag of `spec` when this engine has its image: *out filled, true; false to pack.
Result<bool> FoundInTagCache(docker::DockerApi& api, const ImageSpec& spec, const TagCache& cache,
                             const std::string& doing, std::chrono::steady_clock::time_point pack_start,
                             EnsuredImage* out) {
  auto tag = cache.Lookup(spec);
  if (!tag) return false;
  auto existing = api.InspectImage(*tag);
  if (existing) {
    out->tag = *tag;
    out->from_cache = true;
    out->image_id = existing->id;
    out->image_size_bytes = existing->size_bytes;
    out->pack_s = SecondsSince(pack_start);
    return true;
  }
  if (existing.error().code() != ErrorCode::kNotFound) return existing.error().Context(doing);
  return false;  // not on this engine: pack and build as usual
}

// The stamps of the spec's own files, in executables, plugins, files order.
std::vector<Result<FileStamp>> StampSpecFiles(const ImageSpec& spec) {
  std::vector<Result<FileStamp>> stamps;
  for (const auto* group : {&spec.executables, &spec.plugins, &spec.files}) {
    for (const HostFile& f : *group) stamps.push_back(StampFile(f.host_path));
  }
  return stamps;
}

bool SpecFilesUnchanged(const ImageSpec& spec, const std::vector<Result<FileStamp>>& before) {
  bool unchanged = true;
  std::size_t i = 0;
  for (const auto* group : {&spec.executables, &spec.plugins, &spec.files}) {
    for (const HostFile& f : *group) {
      auto now = StampFile(f.host_path);
      unchanged = unchanged && before[i] && now && *before[i] == *now;
      ++i;
    }
  }
  return unchanged;
}

// Builds the packed context as its tag; the image's id, size and build time into *out.
Status BuildPacked(docker::DockerApi& api, const ImageSpec& spec, PackedContext& ctx,
                   const docker::BuildProgressFn& progress, docker::CancelToken* cancel, const std::string& doing,
                   EnsuredImage* out) {
  docker::BuildRequest request;
  request.context_tar = std::move(ctx.tar);
  request.tags = {ctx.tag};
  request.labels = ImageLabels(spec);
  const auto build_start = std::chrono::steady_clock::now();
  auto built = api.BuildImage(request, progress, cancel);
  if (!built) return built.error().Context(doing);
  out->build_s = SecondsSince(build_start);
  out->built = true;
  out->image_id = built->image_id;
  auto info = api.InspectImage(ctx.tag);
  if (!info) return info.error().Context(doing + ": the built tag is missing");
  out->image_size_bytes = info->size_bytes;
  return Ok{};
}

}  // namespace

Result<EnsuredImage> EnsureImage(docker::DockerApi& api, const ImageSpec& spec,
                                 const docker::BuildProgressFn& progress,
                                 docker::CancelToken* cancel, const TagCache* cache) {
  const std::string doing = "ensuring image " + spec.repository;
  EnsuredImage out;
  const auto pack_start = std::chrono::steady_clock::now();
  if (cache != nullptr) {
    auto found = FoundInTagCache(api, spec, *cache, doing, pack_start, &out);
    if (!found) return found.error();
    if (*found) return out;
  }
  // The spec's own files before packing: a file rewritten while we read it is not remembered.
  std::vector<Result<FileStamp>> before;
  if (cache != nullptr) before = StampSpecFiles(spec);
  auto ctx = PackContext(spec);
  if (!ctx) return ctx.error();
  out.pack_s = SecondsSince(pack_start);
  out.tag = ctx->tag;
  out.context_bytes = ctx->tar.size();
  if (cache != nullptr && SpecFilesUnchanged(spec, before)) {
    (void)cache->Remember(spec, *ctx);  // a failure only costs the next run a pack
  }
  auto existing = api.InspectImage(ctx->tag);
  if (existing) {
    out.image_id = existing->id;
    out.image_size_bytes = existing->size_bytes;
    return out;
  }
  if (existing.error().code() != ErrorCode::kNotFound) return existing.error().Context(doing);
  SWARMBOX_TRY(BuildPacked(api, spec, *ctx, progress, cancel, doing, &out));
  return out;
}

Result<std::vector<std::string>> RemoveStaleImages(docker::DockerApi& api,
                                                   const std::string& repository,
                                                   const std::string& keep_tag) {
  docker::LabelSelector selector;
  selector.equals = {{"swarmbox.image", repository}};
  auto list = api.ListImages(selector);
  if (!list) return list.error().Context("listing images of " + repository);
  std::vector<std::string> removed;
  for (const docker::ImageInfo& image : *list) {
    bool keep = false;
    for (const std::string& tag : image.repo_tags) keep = keep || tag == keep_tag;
    if (keep) continue;
    if (api.RemoveImage(image.id, /*force=*/false)) removed.push_back(image.id);
  }
  return removed;
}

}  // namespace swarmbox::images
