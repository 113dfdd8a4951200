#include "swarmbox/report/provenance.hpp"

#include <unistd.h>

#include <array>

#include "swarmbox/common/version.hpp"
#include "swarmbox/report/results_csv.hpp"

namespace swarmbox::report {

using yaml::Node;

namespace {

Node Str(std::string_view s) { return Node::Scalar(std::string(s), {}, /*quoted=*/true); }

Node Number(const std::optional<double>& v) {
  if (!v) return Node::Null();
  return Node::Scalar(CsvNumber(*v));
}

std::string StringAt(const Node& doc, std::string_view key) {
  const Node* n = doc.Find(key);
  return n != nullptr && n->is_scalar() ? n->scalar() : std::string();
}

std::optional<double> NumberAt(const Node& doc, std::string_view key) {
  const Node* n = doc.Find(key);
  if (n == nullptr || !n->is_scalar()) return std::nullopt;
  return yaml::ScalarAsDouble(n->scalar());
}

}  // namespace

std::string HostName() {
  std::array<char, 256> buf{};
  if (gethostname(buf.data(), buf.size() - 1) != 0) return "";
  return std::string(buf.data());
}

Provenance LocalProvenance() {
  Provenance p;
  const BuildInfo& b = Build();
  p.swarmbox_version = std::string(b.version);
  p.swarmbox_commit = std::string(b.commit);
  p.build_type = std::string(b.build_type);
  p.host_name = HostName();
  return p;
}

Node ProvenanceNode(const Provenance& p) {
  Node doc = Node::Mapping();
  doc.Set("swarmbox_version", Str(p.swarmbox_version));
  doc.Set("swarmbox_commit", Str(p.swarmbox_commit));
  doc.Set("build_type", Str(p.build_type));
  Node images = Node::Sequence();
  for (const std::string& i : p.images) images.Append(Str(i));
  doc.Set("images", std::move(images));
  doc.Set("docker_version", Str(p.engine.docker_version));
  doc.Set("docker_api_version", Str(p.engine.docker_api_version));
  doc.Set("kernel", Str(p.engine.kernel));
  doc.Set("fault_mechanism", Str(p.fault_mechanism));
  doc.Set("rtf_requested", Number(p.rtf_requested));
  doc.Set("rtf_achieved", Number(p.rtf_achieved));
  doc.Set("host_name", Str(p.host_name));
  return doc;
}

Provenance ParseProvenance(const Node& node) {
  Provenance p;
  if (!node.is_mapping()) return p;
  p.swarmbox_version = StringAt(node, "swarmbox_version");
  p.swarmbox_commit = StringAt(node, "swarmbox_commit");
  p.build_type = StringAt(node, "build_type");
  if (const Node* images = node.Find("images"); images != nullptr && images->is_sequence()) {
    for (const Node& i : images->items()) {
      if (i.is_scalar()) p.images.push_back(i.scalar());
    }
  }
  p.engine.docker_version = StringAt(node, "docker_version");
  p.engine.docker_api_version = StringAt(node, "docker_api_version");
  p.engine.kernel = StringAt(node, "kernel");
  p.fault_mechanism = StringAt(node, "fault_mechanism");
  p.rtf_requested = NumberAt(node, "rtf_requested");
  p.rtf_achieved = NumberAt(node, "rtf_achieved");
  p.host_name = StringAt(node, "host_name");
  return p;
}

const std::vector<std::string>& ProvenanceColumns() {
  static const std::vector<std::string> kColumns = {
      "swarmbox_version", "swarmbox_commit", "build_type",      "images",
      "docker_version",   "docker_api_version", "kernel",       "fault_mechanism",
      "rtf_requested",    "rtf_achieved",    "host_name"};
  return kColumns;
}

std::vector<std::string> ProvenanceCells(const Provenance& p) {
  std::string images;
  for (const std::string& i : p.images) images += (images.empty() ? "" : " ") + i;
  return {p.swarmbox_version,
          p.swarmbox_commit,
          p.build_type,
          images,
          p.engine.docker_version,
          p.engine.docker_api_version,
          p.engine.kernel,
          p.fault_mechanism,
          p.rtf_requested ? CsvNumber(*p.rtf_requested) : "",
          p.rtf_achieved ? CsvNumber(*p.rtf_achieved) : "",
          p.host_name};
}

}  // namespace swarmbox::report
