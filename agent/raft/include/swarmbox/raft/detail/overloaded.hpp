// Overloaded: builds one visitor from several lambdas for std::visit over MissionCommand.
//   std::visit(Overloaded{[](const StartSearch& c) {...}, [](const ReturnHome&) {...}}, cmd);
#pragma once

namespace swarmbox::raft::detail {

template <class... Fs>
struct Overloaded : Fs... {
  using Fs::operator()...;
};
template <class... Fs>
Overloaded(Fs...) -> Overloaded<Fs...>;

}  // namespace swarmbox::raft::detail
