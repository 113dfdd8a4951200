// swarmbox-bench: see bench.hpp. `swarmbox-bench --help` lists the suites.
#include <cstdio>
#include <cstdlib>
#include <string>

#include "bench.hpp"
#include "swarmbox/common/version.hpp"

namespace swarmbox::bench {

std::vector<Suite>& MutableSuites() {
  static std::vector<Suite> suites;
  return suites;
}

bool RegisterSuite(Suite suite) {
  MutableSuites().push_back(std::move(suite));
  return true;
}

const std::vector<Suite>& Suites() { return MutableSuites(); }

std::string Args::Get(std::string_view key, std::string_view fallback) const {
  auto it = options.find(std::string(key));
  return it == options.end() ? std::string(fallback) : it->second;
}

double Args::GetDouble(std::string_view key, double fallback) const {
  auto it = options.find(std::string(key));
  return it == options.end() ? fallback : std::strtod(it->second.c_str(), nullptr);
}

long Args::GetInt(std::string_view key, long fallback) const {
  auto it = options.find(std::string(key));
  return it == options.end() ? fallback : std::strtol(it->second.c_str(), nullptr, 10);
}

}  // namespace swarmbox::bench

namespace {

void PrintUsage(std::FILE* out) {
  std::fprintf(out,
               "usage: swarmbox-bench SUITE [--quick] [--key=value ...]\n"
               "       swarmbox-bench all [--quick]\n"
               "       swarmbox-bench --version\n\n"
               "Each suite prints one logfmt line of figures per scenario.\nsuites:\n");
  for (const auto& s : swarmbox::bench::Suites()) {
    std::fprintf(out, "  %-12s %s\n", s.name.c_str(), s.description.c_str());
  }
}

}  // namespace

int main(int argc, char** argv) {
  using swarmbox::bench::Args;
  if (argc < 2 || std::string(argv[1]) == "--help" || std::string(argv[1]) == "-h") {
    PrintUsage(argc < 2 ? stderr : stdout);
    return argc < 2 ? 2 : 0;
  }
  if (std::string(argv[1]) == "--version") {
    std::printf("%s\n", swarmbox::VersionLine("swarmbox-bench").c_str());
    return 0;
  }
  const std::string suite_name = argv[1];
  Args args;
  for (int i = 2; i < argc; ++i) {
    std::string a = argv[i];
    if (a == "--quick") {
      args.quick = true;
    } else if (a.rfind("--", 0) == 0) {
      auto eq = a.find('=');
      if (eq != std::string::npos) {
        args.options[a.substr(2, eq - 2)] = a.substr(eq + 1);
      } else if (i + 1 < argc) {
        args.options[a.substr(2)] = argv[++i];
      } else {
        std::fprintf(stderr, "swarmbox-bench: option %s needs a value\n", a.c_str());
        return 2;
      }
    } else {
      args.positionals.push_back(a);
    }
  }
  int worst = 0;
  bool found = false;
  for (const auto& s : swarmbox::bench::Suites()) {
    if (suite_name == "all" || s.name == suite_name) {
      found = true;
      std::fflush(stdout);
      int rc = s.run(args);
      std::fflush(stdout);
      if (rc != 0) {
        std::fprintf(stderr, "swarmbox-bench: suite %s failed (exit %d)\n", s.name.c_str(), rc);
        worst = rc;
      }
    }
  }
  if (!found) {
    std::fprintf(stderr, "swarmbox-bench: unknown suite '%s'\n", suite_name.c_str());
    PrintUsage(stderr);
    return 2;
  }
  return worst;
}
