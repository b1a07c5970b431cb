// A small streaming JSON writer (objects, arrays, numbers, strings), indented two spaces.
// Non-finite numbers are written as null: JSON has no NaN, and a metric that is undefined
// (no matches, no samples) must read as "no value", not as 0.
// Hand-written because the project's dependencies include no JSON library and the output is a
// few dozen keys; tests read it back with yaml-cpp (YAML 1.2 is a superset of JSON).
#pragma once

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <string>
#include <vector>

namespace vtrack::eval {

class JsonWriter {
 public:
  JsonWriter& BeginObject() { return Open('{'); }
  JsonWriter& EndObject() { return Close('}'); }
  JsonWriter& BeginArray() { return Open('['); }
  JsonWriter& EndArray() { return Close(']'); }

  JsonWriter& Key(const std::string& k) {
    Separate();
    Quote(k);
    out_ += ": ";
    after_key_ = true;
    return *this;
  }
  JsonWriter& Number(double v) {
    Separate();
    if (!std::isfinite(v)) {
      out_ += "null";
    } else {
      char buf[32];
      std::snprintf(buf, sizeof(buf), "%.9g", v);
      out_ += buf;
    }
    return *this;
  }
  JsonWriter& Int(std::int64_t v) {
    Separate();
    out_ += std::to_string(v);
    return *this;
  }
  JsonWriter& Bool(bool v) {
    Separate();
    out_ += v ? "true" : "false";
    return *this;
  }
  JsonWriter& String(const std::string& s) {
    Separate();
    Quote(s);
    return *this;
  }
  // Inserts an already serialised JSON value (e.g. a summary written by another writer).
  JsonWriter& Raw(const std::string& json) {
    Separate();
    std::string indented;
    for (const char c : json) {
      indented += c;
      if (c == '\n') indented += Indent();
    }
    out_ += indented;
    return *this;
  }

  const std::string& str() const { return out_; }

 private:
  JsonWriter& Open(char c) {
    Separate();
    out_ += c;
    first_.push_back(true);
    return *this;
  }
  JsonWriter& Close(char c) {
    const bool empty = first_.back();
    first_.pop_back();
    if (!empty) {
      out_ += '\n';
      out_ += Indent();
    }
    out_ += c;
    return *this;
  }
  // Before a value: a comma and newline unless it is the first in its container, or follows a key.
  void Separate() {
    if (after_key_) {
      after_key_ = false;
      return;
    }
    if (first_.empty()) return;
    if (!first_.back()) out_ += ',';
    first_.back() = false;
    out_ += '\n';
    out_ += Indent();
  }
  std::string Indent() const { return std::string(2 * first_.size(), ' '); }
  void Quote(const std::string& s) {
    out_ += '"';
    for (const unsigned char c : s) {
      switch (c) {
        case '"': out_ += "\\\""; break;
        case '\\': out_ += "\\\\"; break;
        case '\n': out_ += "\\n"; break;
        case '\t': out_ += "\\t"; break;
        case '\r': out_ += "\\r"; break;
        default:
          if (c < 0x20) {
            char buf[8];
            std::snprintf(buf, sizeof(buf), "\\u%04x", c);
            out_ += buf;
          } else {
            out_ += static_cast<char>(c);
          }
      }
    }
    out_ += '"';
  }

  std::string out_;
  std::vector<bool> first_;
  bool after_key_ = false;
};

}  // namespace vtrack::eval
