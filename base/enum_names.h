// Names of an enumeration's values, declared once as a table: conversion both ways and the list
// of choices for messages, without a switch per enumeration.
#pragma once

#include <array>
#include <cstddef>
#include <string>

namespace vtrack {

// An enumeration's names, in the order of its values 0, 1, ...: specialise
// `template <> struct vtrack::EnumNames<E> { static constexpr std::array kNames{...}; };`.
template <class E>
struct EnumNames;

template <class E>
const char* NameOf(E value) {
  const auto& names = EnumNames<E>::kNames;
  const auto i = static_cast<std::size_t>(value);
  return i < names.size() ? names[i] : "?";
}

template <class E>
bool FromName(const std::string& name, E* value) {
  const auto& names = EnumNames<E>::kNames;
  for (std::size_t i = 0; i < names.size(); ++i) {
    if (name == names[i]) {
      *value = static_cast<E>(i);
      return true;
    }
  }
  return false;
}

// "none | band | grid".
template <class E>
std::string Choices() {
  std::string out;
  for (const char* n : EnumNames<E>::kNames) out += (out.empty() ? "" : " | ") + std::string(n);
  return out;
}

}  // namespace vtrack
