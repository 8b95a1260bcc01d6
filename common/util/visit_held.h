// visit_held: std::visit for code that may not throw (the haptic path). It calls the handler
// for the alternative a variant holds, found by its index, where std::visit may throw
// bad_variant_access on a valueless variant: that one gives `otherwise`. The handlers
// (Overloaded, common/util/overloaded.h) must take every alternative and return a Result.
#pragma once

#include <cstddef>
#include <utility>
#include <variant>

namespace cohaptic {

namespace visit_held_detail {
template <class Result, class Variant, class Handlers, std::size_t... Index>
Result visit_by_index(Variant& variant, Handlers& handlers, Result otherwise,
                      std::index_sequence<Index...>) noexcept {
  static_cast<void>(
      ((variant.index() == Index ? (otherwise = handlers(*std::get_if<Index>(&variant)), true)
                                 : false) ||
       ...));
  return otherwise;
}
}  // namespace visit_held_detail

template <class Result, class Variant, class Handlers>
Result visit_held(Variant& variant, Handlers handlers, Result otherwise) noexcept {
  return visit_held_detail::visit_by_index(
      variant, handlers, std::move(otherwise),
      std::make_index_sequence<std::variant_size_v<std::remove_const_t<Variant>>>{});
}

}  // namespace cohaptic
