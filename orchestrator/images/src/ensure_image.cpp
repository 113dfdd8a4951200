#include "swarmbox/images/ensure_image.hpp"

#include <chrono>

#include "swarmbox/images/image_context.hpp"

namespace swarmbox::images {
namespace {

double SecondsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

}  // namespace

Result<EnsuredImage> EnsureImage(docker::DockerApi& api, const ImageSpec& spec,
                                 const docker::BuildProgressFn& progress,
                                 docker::CancelToken* cancel) {
  const std::string doing = "ensuring image " + spec.repository;
  EnsuredImage out;
  const auto pack_start = std::chrono::steady_clock::now();
  auto ctx = PackContext(spec);
  if (!ctx) return ctx.error();
  out.pack_s = SecondsSince(pack_start);
  out.tag = ctx->tag;
  out.context_bytes = ctx->tar.size();

  auto existing = api.InspectImage(ctx->tag);
  if (existing) {
    out.image_id = existing->id;
    out.image_size_bytes = existing->size_bytes;
    return out;
  }
  if (existing.error().code() != ErrorCode::kNotFound) return existing.error().Context(doing);

  docker::BuildRequest request;
  request.context_tar = std::move(ctx->tar);
  request.tags = {ctx->tag};
  request.labels = ImageLabels(spec);
  const auto build_start = std::chrono::steady_clock::now();
  auto built = api.BuildImage(request, progress, cancel);
  if (!built) return built.error().Context(doing);
  out.build_s = SecondsSince(build_start);
  out.built = true;
  out.image_id = built->image_id;
  auto info = api.InspectImage(ctx->tag);
  if (!info) return info.error().Context(doing + ": the built tag is missing");
  out.image_size_bytes = info->size_bytes;
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
