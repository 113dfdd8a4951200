// ParseEngineEndpoint: $DOCKER_HOST and the TLS variables into where DockerClient connects, as the
// docker CLI reads them; every value it cannot honour is an error, never the local socket.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>

#include "swarmbox/docker/engine_endpoint.hpp"
#include "swarmbox/docker/http_transport.hpp"

namespace swarmbox::docker {
namespace {

using ::testing::HasSubstr;
using Kind = EngineEndpoint::Kind;

DockerEnvironment Env(std::string host) {
  DockerEnvironment env;
  env.docker_host = std::move(host);
  env.home = "/home/pilot";
  return env;
}

TEST(ParseEngineEndpoint, UnsetOrEmptyIsTheLocalSocket) {
  for (const char* value : {"", "unix://"}) {
    auto e = ParseEngineEndpoint(Env(value));
    ASSERT_TRUE(e) << e.error().ToString();
    EXPECT_EQ(e->kind, Kind::kUnix);
    EXPECT_EQ(e->socket_path, "/var/run/docker.sock");
    EXPECT_EQ(e->ToString(), "unix:///var/run/docker.sock");
    EXPECT_EQ(e->BaseUrl(), "http://docker");
  }
}

TEST(ParseEngineEndpoint, UnixTakesThePath) {
  auto e = ParseEngineEndpoint(Env("unix:///run/user/1000/docker.sock"));
  ASSERT_TRUE(e);
  EXPECT_EQ(e->kind, Kind::kUnix);
  EXPECT_EQ(e->socket_path, "/run/user/1000/docker.sock");
  auto relative = ParseEngineEndpoint(Env("unix://docker.sock"));
  ASSERT_FALSE(relative);
  EXPECT_THAT(relative.error().message(), HasSubstr("must be absolute"));
}

TEST(ParseEngineEndpoint, TcpIsPlainHttpWithTheDockerDefaultPort) {
  auto e = ParseEngineEndpoint(Env("tcp://10.0.0.5:2375"));
  ASSERT_TRUE(e) << e.error().ToString();
  EXPECT_EQ(e->kind, Kind::kTcp);
  EXPECT_EQ(e->host, "10.0.0.5");
  EXPECT_EQ(e->port, 2375);
  EXPECT_FALSE(e->tls);
  EXPECT_EQ(e->BaseUrl(), "http://10.0.0.5:2375");
  EXPECT_EQ(e->ToString(), "tcp://10.0.0.5:2375");

  auto no_port = ParseEngineEndpoint(Env("tcp://build-box/"));
  ASSERT_TRUE(no_port) << no_port.error().ToString();
  EXPECT_EQ(no_port->port, 2375);

  auto v6 = ParseEngineEndpoint(Env("tcp://[::1]:2400"));
  ASSERT_TRUE(v6) << v6.error().ToString();
  EXPECT_EQ(v6->host, "::1");
  EXPECT_EQ(v6->BaseUrl(), "http://[::1]:2400");
}

TEST(ParseEngineEndpoint, TlsVerifyUsesTheCertPathFilesAndPort2376) {
  DockerEnvironment env = Env("tcp://docker.example");
  env.tls_verify = "1";
  env.cert_path = "/etc/swarm-certs";
  auto e = ParseEngineEndpoint(env);
  ASSERT_TRUE(e) << e.error().ToString();
  EXPECT_TRUE(e->tls);
  EXPECT_TRUE(e->tls_verify);
  EXPECT_EQ(e->port, 2376);
  EXPECT_EQ(e->ca_file, "/etc/swarm-certs/ca.pem");
  EXPECT_EQ(e->cert_file, "/etc/swarm-certs/cert.pem");
  EXPECT_EQ(e->key_file, "/etc/swarm-certs/key.pem");
  EXPECT_EQ(e->BaseUrl(), "https://docker.example:2376");
  EXPECT_EQ(e->ToString(), "tcp://docker.example:2376 (TLS)");

  // Without DOCKER_CERT_PATH: ~/.docker, as the docker CLI.
  env.cert_path.clear();
  auto home = ParseEngineEndpoint(env);
  ASSERT_TRUE(home);
  EXPECT_EQ(home->ca_file, "/home/pilot/.docker/ca.pem");
}

TEST(ParseEngineEndpoint, DockerTlsAloneEncryptsWithoutCheckingTheEngine) {
  DockerEnvironment env = Env("tcp://10.0.0.5:2376");
  env.tls = "1";
  auto e = ParseEngineEndpoint(env);
  ASSERT_TRUE(e);
  EXPECT_TRUE(e->tls);
  EXPECT_FALSE(e->tls_verify);
  EXPECT_TRUE(e->ca_file.empty());
  EXPECT_EQ(e->cert_file, "/home/pilot/.docker/cert.pem");
  EXPECT_THAT(e->ToString(), HasSubstr("not checked"));
}

TEST(ParseEngineEndpoint, TlsVariablesDoNotApplyToAUnixSocket) {
  DockerEnvironment env = Env("unix:///var/run/docker.sock");
  env.tls_verify = "1";
  auto e = ParseEngineEndpoint(env);
  ASSERT_TRUE(e);
  EXPECT_EQ(e->kind, Kind::kUnix);
  EXPECT_FALSE(e->tls);
}

TEST(ParseEngineEndpoint, EverythingElseIsAnErrorThatSaysWhy) {
  struct Case {
    const char* value;
    const char* says;
  };
  for (const Case& c : {Case{"ssh://me@build-box", "swarmbox experiment --hosts ssh://me@build-box"},
                        Case{"ssh://me@build-box", "ssh -nNT -L /tmp/docker.sock:/var/run/docker.sock me@build-box"},
                        Case{"npipe:////./pipe/docker_engine", "unknown scheme 'npipe'"},
                        Case{"fd://", "unknown scheme 'fd'"},
                        Case{"10.0.0.5:2375", "the scheme is missing"},
                        Case{"tcp://:2375", "no host"},
                        Case{"tcp://h:0", "not a number in 1..65535"},
                        Case{"tcp://h:70000", "not a number in 1..65535"},
                        Case{"tcp://h:23x", "not a number"},
                        Case{"tcp://h:2375/v1.41", "a path after the address"},
                        Case{"tcp://[::1", "unclosed '['"}}) {
    auto e = ParseEngineEndpoint(Env(c.value));
    ASSERT_FALSE(e) << c.value << " parsed as " << e->ToString();
    EXPECT_EQ(e.error().code(), ErrorCode::kInvalidArgument) << c.value;
    EXPECT_EQ(e.error().where(), "DOCKER_HOST");
    EXPECT_THAT(e.error().message(), HasSubstr(std::string("DOCKER_HOST=") + c.value)) << c.value;
    EXPECT_THAT(e.error().message(), HasSubstr(c.says)) << c.value;
  }
}

// The process environment, with the docker CLI's handling of missing certificate files.
class EngineFromEnvironment : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = std::filesystem::temp_directory_path() / ("swarmbox-engine-env-" + std::to_string(::getpid()));
    std::filesystem::create_directories(dir_);
  }
  void TearDown() override {
    for (const char* v : {"DOCKER_HOST", "DOCKER_TLS_VERIFY", "DOCKER_TLS", "DOCKER_CERT_PATH"}) ::unsetenv(v);
    std::filesystem::remove_all(dir_);
  }
  void Touch(const char* name) { std::ofstream(dir_ / name) << "pem\n"; }
  std::filesystem::path dir_;
};

TEST_F(EngineFromEnvironment, MissingCertificateFilesAreDroppedAsTheDockerCliDoes) {
  ::setenv("DOCKER_HOST", "tcp://127.0.0.1:2376", 1);
  ::setenv("DOCKER_TLS_VERIFY", "1", 1);
  ::setenv("DOCKER_CERT_PATH", dir_.c_str(), 1);
  Touch("ca.pem");
  auto ca_only = EngineEndpointFromEnvironment();
  ASSERT_TRUE(ca_only) << ca_only.error().ToString();
  EXPECT_EQ(ca_only->ca_file, (dir_ / "ca.pem").string());
  EXPECT_TRUE(ca_only->cert_file.empty());
  Touch("cert.pem");
  auto half = EngineEndpointFromEnvironment();
  ASSERT_FALSE(half);
  EXPECT_THAT(half.error().message(), HasSubstr("cert.pem is there but not key.pem"));
  Touch("key.pem");
  auto all = EngineEndpointFromEnvironment();
  ASSERT_TRUE(all);
  EXPECT_EQ(all->key_file, (dir_ / "key.pem").string());
}

TEST_F(EngineFromEnvironment, ATcpEngineThatIsNotThereIsNamedInTheError) {
  // Port 1 on loopback: refused at once; the transport must not try the local socket instead.
  CurlTransport t(*ParseEngineEndpoint(Env("tcp://127.0.0.1:1")), std::chrono::seconds(2));
  HttpRequest req;
  req.target = "/_ping";
  auto r = t.Send(req, nullptr, nullptr);
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().code(), ErrorCode::kUnavailable);
  EXPECT_THAT(r.error().message(), HasSubstr("no Docker engine answers at tcp://127.0.0.1:1"));
  EXPECT_THAT(r.error().where(), HasSubstr("tcp://127.0.0.1:1"));
}

}  // namespace
}  // namespace swarmbox::docker
