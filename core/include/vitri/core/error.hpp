#pragma once
/// @file error.hpp
/// The exception hierarchy. Every error that bad input can cause derives from vitri::Error and carries
/// the data that identifies the culprit (an index, a file and line, a value). Broken internal invariants
/// are asserts, not exceptions.

#include <cstddef>
#include <stdexcept>
#include <string>
#include <utility>

namespace vitri {

/// Base of every exception vitri throws on bad input or unmet preconditions.
class Error : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// An argument is out of its documented domain (NaN, infinity, negative precision, empty input, ...).
class InvalidArgument : public Error {
 public:
  using Error::Error;
};

/// A point or constraint with a given index is unusable (non-finite, duplicate, outside the domain).
class InvalidPoint : public InvalidArgument {
 public:
  InvalidPoint(std::size_t index, const std::string& what)
      : InvalidArgument("point " + std::to_string(index) + ": " + what), index_(index) {}
  /// Index of the offending point in the caller's numbering.
  std::size_t index() const { return index_; }

 private:
  std::size_t index_;
};

/// A file could not be read or parsed; carries the file name and the 1-based line (0 when not known).
class ParseError : public Error {
 public:
  ParseError(std::string file, std::size_t line, const std::string& what)
      : Error(file + (line ? ":" + std::to_string(line) : std::string()) + ": " + what),
        file_(std::move(file)),
        line_(line) {}
  const std::string& file() const { return file_; }
  std::size_t line() const { return line_; }

 private:
  std::string file_;
  std::size_t line_;
};

/// A numerical problem that the input causes: singular or ill-conditioned fit, undetermined polynomial.
class NumericalError : public Error {
 public:
  using Error::Error;
};

/// A documented size limit was reached (index type overflow, memory budget).
class LimitError : public Error {
 public:
  using Error::Error;
};

}  // namespace vitri
