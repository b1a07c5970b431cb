#include "tracker/config.h"

#include <yaml-cpp/yaml.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <stdexcept>
#include <type_traits>

namespace vtrack {
namespace {

[[noreturn]] void Fail(const std::string& origin, const std::string& key, const std::string& what) {
  throw std::runtime_error(origin + ": " + key + " " + what);
}

// The value as written, for an error message: a scalar as is, a list or map in flow style
// ("[1, 2]", "{a: 1}"), nothing as "".
std::string Scalar(const YAML::Node& n) {
  if (n.IsScalar()) return n.Scalar();
  if (!n.IsDefined() || n.IsNull()) return "";
  YAML::Emitter out;  // YAML::Flow is the emitter's manipulator; on a std::ostream it prints a number
  out << YAML::Flow << n;
  return out.c_str();
}

template <class T>
const char* TypeName() {
  if constexpr (std::is_same_v<T, bool>) return "boolean";
  else if constexpr (std::is_integral_v<T>) return "integer";
  else return "number";
}

// Refuses a mapping that holds a key twice (yaml-cpp keeps both; a lookup would see the first).
void RefuseDuplicates(const YAML::Node& map, const std::string& origin, const std::string& prefix) {
  std::map<std::string, int> line_of;
  for (const auto& kv : map) {
    const std::string k = kv.first.as<std::string>();
    const int line = kv.first.Mark().line + 1;
    const auto [it, fresh] = line_of.emplace(k, line);
    if (!fresh) {
      Fail(origin, prefix + k, "appears twice (lines " + std::to_string(it->second) + " and " +
                                   std::to_string(line) + ")");
    }
  }
}

// Reads the keys of one mapping into the fields its Visit declares; Done() refuses the keys it
// does not know.
class MapReader {
 public:
  MapReader(const YAML::Node& node, std::string origin, std::string prefix)
      : node_(node), origin_(std::move(origin)), prefix_(std::move(prefix)) {}

  template <class T>
  void operator()(const char* key, T* value, const param::Info& /*info*/) {
    known_.insert(key);
    const YAML::Node v = node_[key];  // node_ is const: the look-up inserts nothing
    if (!v) return;
    const std::string where = prefix_ + key;
    if constexpr (std::is_enum_v<T>) {
      const std::string s = v.IsScalar() ? v.Scalar() : Scalar(v);
      if (!FromName(s, value)) Fail(origin_, where, "= '" + s + "': must be " + Choices<T>());
    } else if constexpr (requires { value->front().Visit(*this); }) {
      ReadList(v, where, value);
    } else {
      try {
        *value = v.as<T>();
      } catch (const YAML::Exception&) {
        Fail(origin_, where, "= '" + Scalar(v) + "' is not a valid " + TypeName<T>());
      }
    }
  }

  void Done() const {
    RefuseDuplicates(node_, origin_, prefix_);
    for (const auto& kv : node_) {
      const std::string k = kv.first.as<std::string>();
      if (!known_.count(k)) Fail(origin_, prefix_ + k, "is not a known key");
    }
  }

 private:
  template <class Item>
  void ReadList(const YAML::Node& list, const std::string& where, std::vector<Item>* out) {
    if (!list.IsSequence()) Fail(origin_, where, "must be a list of mappings");
    out->clear();
    for (std::size_t i = 0; i < list.size(); ++i) {
      const std::string item_where = where + "[" + std::to_string(i) + "]";
      if (!list[i].IsMap()) Fail(origin_, item_where, "must be a mapping");
      Item item;
      MapReader reader(list[i], origin_, item_where + ".");
      item.Visit(reader);
      reader.Done();
      out->push_back(item);
    }
  }

  const YAML::Node node_;
  std::string origin_, prefix_;
  std::set<std::string> known_;
};

void Read(const YAML::Node& root, const std::string& origin, TrackerParams* p) {
  if (root.IsNull()) Fail(origin, "(the whole file)", "holds no section: an empty config is refused");
  if (!root.IsMap()) Fail(origin, "top level", "is not a mapping of sections");
  RefuseDuplicates(root, origin, "");
  std::set<std::string> sections;
  p->VisitSections([&](auto* section) {
    using Section = std::remove_pointer_t<decltype(section)>;
    const std::string name = Section::kSection;
    sections.insert(name);
    const YAML::Node node = root[name];
    if (!node || node.IsNull()) return;
    if (!node.IsMap()) Fail(origin, name, "is not a mapping");
    MapReader reader(node, origin, name + ".");
    section->Visit(reader);
    reader.Done();
  });
  for (const auto& kv : root) {
    const std::string s = kv.first.as<std::string>();
    if (!sections.count(s)) {
      std::string names;
      for (const std::string& n : sections) names += (names.empty() ? "" : ", ") + n;
      Fail(origin, s, "is not a known section (" + names + ")");
    }
  }
  std::string error;
  if (!p->Validate(&error)) throw std::runtime_error(origin + ": " + error);
}

// Lists of mappings longer than this are written one item per line (an ensemble's tree nodes),
// shorter ones on the key's line.
constexpr std::size_t kFlowListItems = 40;

// A field's value as YAML writes it (lists of mappings in flow style).
class ValueText {
 public:
  template <class T>
  void operator()(const char* key, T* value, const param::Info& /*info*/) {
    if (!text_.empty()) text_ += ", ";
    if (nested_) text_ += std::string(key) + ": ";
    text_ += Of(value);
  }
  template <class T>
  static std::string Of(T* value) {
    if constexpr (std::is_enum_v<T>) {
      return NameOf(*value);
    } else if constexpr (requires { value->front().Visit(std::declval<ValueText&>()); }) {
      std::string out = "[";
      const std::vector<std::string> items = Items(value);
      for (std::size_t i = 0; i < items.size(); ++i) out += (i ? ", " : "") + items[i];
      return out + "]";
    } else {
      return param::Format(*value);
    }
  }
  // Each item of a list of mappings in flow style, "{key: value, ...}".
  template <class T>
  static std::vector<std::string> Items(std::vector<T>* value) {
    std::vector<std::string> out;
    for (T& v : *value) {
      ValueText item;
      item.nested_ = true;
      v.Visit(item);
      out.push_back("{" + item.text_ + "}");
    }
    return out;
  }

 private:
  bool nested_ = false;
  std::string text_;
};

// The valid values of a field as the reference shows them; for a list, those of its items' keys.
template <class T>
std::string ValidText([[maybe_unused]] T* value, const param::Info& info) {
  if constexpr (std::is_enum_v<T>) {
    return Choices<T>();
  } else if constexpr (std::is_same_v<T, bool>) {
    return "true or false";
  } else if constexpr (std::is_arithmetic_v<T>) {
    return info.range.ToString();
  } else {
    typename T::value_type item;
    std::string out;
    auto key_range = [&](const char* key, auto* field, const param::Info& field_info) {
      out += (out.empty() ? "" : "; ") + std::string(key) + " " + ValidText(field, field_info);
    };
    item.Visit(key_range);
    return "items: " + out;
  }
}

// A Markdown table cell: '|' escaped.
std::string Cell(const std::string& text) {
  std::string out;
  for (char c : text) {
    if (c == '|') out += '\\';
    out += c;
  }
  return out;
}

}  // namespace

TrackerParams ParseTrackerParams(const std::string& yaml_text, const std::string& origin) {
  YAML::Node root;
  try {
    root = YAML::Load(yaml_text);
  } catch (const YAML::Exception& e) {
    throw std::runtime_error(origin + ": not valid YAML: " + e.what());
  }
  TrackerParams p;
  Read(root, origin, &p);
  return p;
}

TrackerParams LoadTrackerParams(const std::string& path) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) {
    throw std::runtime_error("tracker config '" + path + "' is not a readable file" +
                             (std::filesystem::is_directory(path, ec) ? " (a directory)" : ""));
  }
  std::ifstream in(path);
  if (!in) throw std::runtime_error("cannot read tracker config '" + path + "'");
  std::ostringstream ss;
  ss << in.rdbuf();
  return ParseTrackerParams(ss.str(), path);
}

void WriteConfigYaml(const TrackerParams& params, std::ostream& out) {
  out << "# vtrack-tracker parameters: one section per component, every key with its unit and\n"
         "# reason (docs/parameters.md lists the valid ranges). A missing key keeps its default;\n"
         "# an unknown, duplicate or invalid key stops the tracker with a message naming it.\n"
         "# Written by `vtrack-tracker --print-config`: the built-in defaults.\n";
  TrackerParams copy = params;
  copy.VisitSections([&](auto* section) {
    using Section = std::remove_pointer_t<decltype(section)>;
    out << "\n" << Section::kSection << ":  # " << Section::kAbout << "\n";
    auto line = [&](const char* key, auto* value, const param::Info& info) {
      if constexpr (requires { ValueText::Items(value); }) {
        if (value->size() > kFlowListItems) {  // a long list: one item per line
          out << "  " << key << ":  # [" << info.unit << "] " << info.reason << "\n";
          for (const std::string& item : ValueText::Items(value)) out << "    - " << item << "\n";
          return;
        }
      }
      std::string entry = std::string("  ") + key + ": " + ValueText::Of(value);
      if (entry.size() < 34) entry.resize(34, ' ');
      out << entry << "  # [" << info.unit << "] " << info.reason << "\n";
    };
    section->Visit(line);
  });
}

void WriteParameterReference(std::ostream& out) {
  out << "# Tracker parameters\n\n"
         "Every parameter of `vtrack-tracker`, as its code declares it: YAML key, built-in default,\n"
         "unit, valid values and what it decides. `config/tracker.yaml` holds the same defaults.\n"
         "A config file names only what it changes; an unknown or duplicate key, a value of the\n"
         "wrong type or out of its range stops the tracker with a message naming the file, the key\n"
         "and the value. Written by `vtrack-tracker --print-parameter-reference`; ctest\n"
         "`parameters_current_test` fails when this file or `config/tracker.yaml` is out of date.\n";
  TrackerParams defaults;
  defaults.VisitSections([&](auto* section) {
    using Section = std::remove_pointer_t<decltype(section)>;
    out << "\n## `" << Section::kSection << "`\n\n" << Section::kAbout << ".\n\n"
        << "| key | default | unit | valid | reason |\n| --- | --- | --- | --- | --- |\n";
    auto row = [&](const char* key, auto* value, const param::Info& info) {
      std::string shown = ValueText::Of(value);
      if constexpr (requires { ValueText::Items(value); }) {
        if (value->size() > kFlowListItems) {
          shown = std::to_string(value->size()) + " items (listed in `config/tracker.yaml`)";
        }
      }
      out << "| `" << key << "` | " << Cell(shown) << " | " << info.unit << " | "
          << Cell(ValidText(value, info)) << " | " << Cell(info.reason) << " |\n";
    };
    section->Visit(row);
  });
}

}  // namespace vtrack
