// BodyKinds: the kinds of deformable body a scene may ask for, listed once. Every per-kind
// variant of the project is declared as PerKind<ForKind<Kind, Type>...>::variant, one entry
// per kind in this list's order: the scene's spec, the compiled model, the simulation, the
// IR body, the prepared IR body and the evaluator's state. A static_assert holds each
// declaration to the list, so a kind added here fails to compile in every layer that has
// no type for it yet, and alternative i of every variant is the same kind, whose index is
// body_kind_index<Kind>. Includes nothing of the project's.
#pragma once

#include <cstddef>
#include <type_traits>
#include <variant>

namespace cohaptic {

/// The kinds, as tags (their types live with their layers).
struct LinearElasticKind {};  ///< tetrahedra condensed for the clients (the protocol paper's)
struct MassSpringKind {};     ///< a mass-spring network (the thin-objects paper's)
struct HomeSpringKind {};     ///< a surface held by home springs (the laparoscopy paper's)
struct SeparationKind {};     ///< two layers that separate (the separation paper's)

template <class... Kinds>
struct KindList {};

/// The one list, in the order of every per-kind variant.
using BodyKinds = KindList<LinearElasticKind, MassSpringKind, HomeSpringKind, SeparationKind>;

/// One layer's type for one kind.
template <class Kind, class Type>
struct ForKind {
  using kind = Kind;
  using type = Type;
};

/// A layer's variant over the kinds: one ForKind entry per kind of BodyKinds, in its order.
template <class... Entries>
struct PerKind {
  static_assert(std::is_same_v<KindList<typename Entries::kind...>, BodyKinds>,
                "a per-kind variant names one type for every kind of BodyKinds, in its order "
                "(common/kinds/body_kinds.h)");
  using variant = std::variant<typename Entries::type...>;
};

namespace body_kinds_detail {

template <class Kind, class List>
struct IndexIn;
template <class Kind, class... Rest>
struct IndexIn<Kind, KindList<Kind, Rest...>> : std::integral_constant<std::size_t, 0> {};
template <class Kind, class First, class... Rest>
struct IndexIn<Kind, KindList<First, Rest...>>
    : std::integral_constant<std::size_t, 1 + IndexIn<Kind, KindList<Rest...>>::value> {};

template <class List>
struct CountOf;
template <class... Kinds>
struct CountOf<KindList<Kinds...>> : std::integral_constant<std::size_t, sizeof...(Kinds)> {};

}  // namespace body_kinds_detail

/// How many kinds there are: the size of every per-kind variant.
inline constexpr std::size_t kBodyKindCount = body_kinds_detail::CountOf<BodyKinds>::value;

/// Kind's place in BodyKinds: its alternative's index in every per-kind variant.
template <class Kind>
inline constexpr std::size_t body_kind_index = body_kinds_detail::IndexIn<Kind, BodyKinds>::value;

}  // namespace cohaptic
