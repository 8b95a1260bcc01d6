// Overloaded: one visitor from several handlers, for std::visit over a variant with one
// handler per alternative, Overloaded{[](const A&) {...}, [](const B&) {...}}. An
// alternative no handler takes fails to compile, where a chain of get_if would fall through.
#pragma once

namespace cohaptic {

template <class... Handlers>
struct Overloaded : Handlers... {
  using Handlers::operator()...;
};
template <class... Handlers>
Overloaded(Handlers...) -> Overloaded<Handlers...>;

}  // namespace cohaptic
