// Packing an ImageSpec into a deterministic `FROM scratch` build context, named by content hash.
//
//   Result<PackedContext> ctx = PackContext(spec);       // reads host files, runs the loader
//   ctx->tag       // "swarmbox/physics:3f2a9c01d4e5b6a7" (first 16 hex digits of the SHA-256)
//   ctx->tar       // Dockerfile + rootfs/..., ready for DockerApi::BuildImage
//
// Layout of the context: `Dockerfile` and `rootfs/<image path>` for every file, with explicit
// parent directories (0755), entries sorted by path, mtime 0, owner 0:0. Equal inputs give equal
// bytes, hence equal tags, so an unchanged image is never rebuilt. The Dockerfile copies rootfs/ to
// / and sets ENV, WORKDIR, USER, ENTRYPOINT and CMD from the spec; labels go with the build request.
#pragma once

#include <map>
#include <string>
#include <vector>

#include "swarmbox/common/result.hpp"
#include "swarmbox/docker/tar_archive.hpp"
#include "swarmbox/images/image_spec.hpp"

namespace swarmbox::images {

inline constexpr std::size_t kTagHashDigits = 16;

struct PackedContext {
  std::string tar;
  std::string tag;           // repository:<hash prefix>
  std::string content_hash;  // full SHA-256 of `tar`, hex
  std::vector<std::string> image_paths;  // every file, directory and link put in the image
  std::size_t payload_bytes = 0;         // sum of the file sizes
  // Every host file read (the spec's files and the library closure; PackContext only).
  std::vector<std::string> host_files;
};

// The generated Dockerfile (pure).
std::string GenerateDockerfile(const ImageSpec& spec);
// The image's labels: spec.labels plus swarmbox.component and swarmbox.image (= repository). They
// are passed with the build request (no builder step) and named in the Dockerfile's comment.
std::map<std::string, std::string> ImageLabels(const ImageSpec& spec);

// Pure: the context from already-read rootfs entries (paths absolute in the image). Adds the parent
// directories, sorts, tars and hashes. kInvalidArgument on two entries with the same path or a
// relative path.
Result<PackedContext> AssembleContext(const ImageSpec& spec, std::vector<docker::TarEntry> rootfs);

// Reads the spec's host files, adds the shared-library closure of executables and plugins, then
// AssembleContext. Errors name the file (missing, not ELF, library not found).
Result<PackedContext> PackContext(const ImageSpec& spec);

}  // namespace swarmbox::images
