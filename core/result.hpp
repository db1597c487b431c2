#pragma once
/// Error values for bad user input: a Result holds either a value or a message that names the problem.
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>

namespace balloon {

/// A value, or an error message meant for the user ("face 12 has a zero area").
template <class T>
class Result {
 public:
  Result(T value) : m_value(std::move(value)) {}  // NOLINT: implicit on purpose, reads like `return mesh;`
  static Result failure(std::string message) {
    Result r;
    r.m_error = std::move(message);
    return r;
  }
  bool ok() const { return m_value.has_value(); }
  explicit operator bool() const { return ok(); }
  const std::string& error() const { return m_error; }
  T& value() {
    if (!m_value) throw std::logic_error("Result::value() on an error: " + m_error);
    return *m_value;
  }
  const T& value() const {
    if (!m_value) throw std::logic_error("Result::value() on an error: " + m_error);
    return *m_value;
  }
  T* operator->() { return &value(); }
  const T* operator->() const { return &value(); }
  T& operator*() { return value(); }
  const T& operator*() const { return value(); }

 private:
  Result() = default;
  std::optional<T> m_value;
  std::string m_error;
};

/// Shorthand for returning an error from a function returning Result<T>.
struct Failure {
  std::string message;
  template <class T>
  operator Result<T>() const {  // NOLINT: implicit on purpose
    return Result<T>::failure(message);
  }
};
inline Failure fail(std::string message) { return Failure{std::move(message)}; }

}  // namespace balloon
