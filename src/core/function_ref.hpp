#pragma once
// A non-owning reference to a callable (as C++26's std::function_ref): no allocation and one
// indirect call, where std::function would copy a capturing lambda to the heap. Private to the
// core: the floating-point decisions pass their exact-sign and root callbacks so, once per
// decision. The referenced callable must outlive the reference (pass it down, never store it).

#include <memory>
#include <type_traits>
#include <utility>

namespace kinetic {

template <class Signature>
class FunctionRef;

template <class R, class... Args>
class FunctionRef<R(Args...)> {
 public:
  template <class F,
            class = std::enable_if_t<!std::is_same_v<std::remove_cvref_t<F>, FunctionRef>>>
  FunctionRef(F&& f)  // NOLINT(google-explicit-constructor): a parameter type, as std::function
      : object_(const_cast<void*>(static_cast<const void*>(std::addressof(f)))),
        call_([](void* object, Args... args) -> R {
          return (*static_cast<std::remove_reference_t<F>*>(object))(
              std::forward<Args>(args)...);
        }) {}

  R operator()(Args... args) const { return call_(object_, std::forward<Args>(args)...); }

 private:
  void* object_;
  R (*call_)(void*, Args...);
};

}  // namespace kinetic
