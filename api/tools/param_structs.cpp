// Build-time tool: a typed parameter struct per technique, generated from the merged render request
// schema (merge_schema's output), so a technique reads its parameters as fields checked by the
// compiler instead of by string name, and no default or enum value is written outside its descriptor
// (renderer/techniques/<name>/<name>.json; issue 33, docs/API.md "A technique declares itself").
//   param_structs <render_request.merged.json> <out dir> <technique>...
// writes <out dir>/<technique>_params.h for each named technique, only when its text changes (an edit
// of one descriptor recompiles the technique that reads it, not every technique):
//   struct CausticsParams {
//     int cube_resolution;                       // integer (integer enums too; std::int64_t past int)
//     double area_weight;                        // number
//     bool energy_check;                         // boolean
//     enum class Method { kTriangles, kSplat };  // string with an enum: its values, in schema order
//     Method method;
//     std::string receivers;                     // string without an enum
//     struct Given { bool cube_resolution = false; ... } given;  // the keys the request set itself
//     template <class P> static CausticsParams from(const P& params);  // P: renderer's Params
//     static const char* toString(Method);       // the schema's spelling
//   };
// A parameter or enum value that cannot become a C++ name fails the build, naming it.
#include <cctype>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <set>
#include <sstream>
#include <stdexcept>
#include <string>

#include <nlohmann/json.hpp>

using nlohmann::json;

namespace {

std::string camel(const std::string& snake) {
  std::string out;
  bool up = true;
  for (char c : snake) {
    if (c == '_') {
      up = true;
      continue;
    }
    out += up ? static_cast<char>(std::toupper(static_cast<unsigned char>(c))) : c;
    up = false;
  }
  return out;
}

bool isIdentifier(const std::string& s) {
  if (s.empty() || std::isdigit(static_cast<unsigned char>(s[0]))) return false;
  for (char c : s)
    if (!std::isalnum(static_cast<unsigned char>(c)) && c != '_') return false;
  static const std::set<std::string> kKeywords{
      "alignas", "alignof", "and", "asm", "auto", "bool", "break", "case", "catch", "char", "class", "const",
      "constexpr", "continue", "default", "delete", "do", "double", "else", "enum", "explicit", "export", "extern",
      "false", "float", "for", "friend", "goto", "if", "inline", "int", "long", "mutable", "namespace", "new",
      "noexcept", "not", "nullptr", "operator", "or", "private", "protected", "public", "register", "return",
      "short", "signed", "sizeof", "static", "struct", "switch", "template", "this", "throw", "true", "try",
      "typedef", "typename", "union", "unsigned", "using", "virtual", "void", "volatile", "while", "given",
      "from", "toString"};
  return !kKeywords.count(s);
}

// "screen_parallel" -> kScreenParallel, "2d" -> k2d.
std::string enumerator(const std::string& value) {
  for (char c : value)
    if (!std::isalnum(static_cast<unsigned char>(c)) && c != '_')
      throw std::runtime_error("enum value \"" + value + "\" cannot become a C++ name");
  std::string out = "k";  // appended, not "k" + ...: GCC 12's false -Wrestrict on operator+(const char*, string&&)
  out += camel(value);
  return out;
}

std::string comment(const std::string& name, const json& p) {
  std::ostringstream c;
  c << "// " << name << ": " << p["type"].get<std::string>();
  if (p.contains("minimum")) c << " in [" << p["minimum"].dump() << ", " << p["maximum"].dump() << "]";
  if (p.contains("enum")) c << " of " << p["enum"].dump();
  c << ", default " << p["default"].dump();
  return c.str();
}

std::string header(const std::string& technique, const json& props) {
  const std::string type = camel(technique) + "Params";
  std::ostringstream h, fields, given, from, enums;
  for (const auto& [name, p] : props.items()) {
    if (!isIdentifier(name)) throw std::runtime_error(technique + ": parameter \"" + name + "\" cannot be a field name");
    const std::string t = p.at("type");
    fields << "  " << comment(name, p) << "\n";
    given << "    bool " << name << " = false;\n";
    if (t == "string" && p.contains("enum")) {
      const std::string e = camel(name);
      enums << "  enum class " << e << " {";
      std::ostringstream parse, print;
      bool first = true;
      for (const auto& v : p["enum"]) {
        const std::string value = v.get<std::string>(), k = enumerator(value);
        enums << (first ? " " : ", ") << k;
        first = false;
        parse << "    if (s == \"" << value << "\") return " << e << "::" << k << ";\n";
        print << "      case " << e << "::" << k << ": return \"" << value << "\";\n";
      }
      enums << " };\n";
      enums << "  static " << e << " parse" << e << "(const std::string& s) {\n"
            << parse.str() << "    throw std::logic_error(\"" << technique << "." << name
            << ": \\\"\" + s + \"\\\" is not in its enum\");\n  }\n";
      enums << "  static const char* toString(" << e << " v) {\n    switch (v) {\n"
            << print.str() << "    }\n    return \"\";\n  }\n";
      fields << "  " << e << " " << name << ";\n";
      from << "    out." << name << " = parse" << e << "(params.template get<std::string>(\"" << name << "\"));\n";
    } else {
      // An integer whose range does not fit an int (illumination_network's 32-bit unsigned seed) is 64-bit.
      const bool wide = t == "integer" && p.contains("minimum") &&
                        (p["minimum"].get<double>() < -2147483648.0 || p["maximum"].get<double>() > 2147483647.0);
      const std::string ct = t == "integer" ? (wide ? "std::int64_t" : "int")
                             : t == "number" ? "double"
                             : t == "boolean" ? "bool"
                                              : "std::string";
      fields << "  " << ct << " " << name << ";\n";
      from << "    out." << name << " = params.template get<" << ct << ">(\"" << name << "\");\n";
    }
    from << "    out.given." << name << " = params.given(\"" << name << "\");\n";
  }
  h << "// Generated by radiant_param_structs (api/tools/param_structs.cpp) from the schema of the technique\n"
    << "// \"" << technique << "\" (renderer/techniques/" << technique << "/" << technique
    << ".json): do not edit.\n"
    << "#pragma once\n#include <cstdint>\n#include <stdexcept>\n#include <string>\n\nnamespace radiant {\n\n"
    << "struct " << type << " {\n"
    << "  static constexpr const char* kTechnique = \"" << technique << "\";\n"
    << enums.str() << fields.str()
    << "  // The keys the request set itself (not a default, preset or budget choice).\n"
    << "  struct Given {\n" << given.str() << "  } given;\n\n"
    << "  // From the technique's Params (renderer/frame/Technique.h), validated with every default filled in.\n"
    << "  template <class P>\n  static " << type << " from(const P& params) {\n    " << type << " out;\n"
    << from.str() << "    return out;\n  }\n};\n\n}  // namespace radiant\n";
  return h.str();
}

void writeIfChanged(const std::filesystem::path& path, const std::string& text) {
  {
    std::ifstream in(path, std::ios::binary);
    if (in) {
      std::ostringstream old;
      old << in.rdbuf();
      if (old.str() == text) return;
    }
  }
  std::ofstream out(path, std::ios::binary);
  out << text;
  if (!out) throw std::runtime_error(path.string() + ": cannot write");
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 4) {
    std::cerr << "usage: param_structs <render_request.merged.json> <out dir> <technique>...\n";
    return 2;
  }
  try {
    std::ifstream in(argv[1]);
    if (!in) throw std::runtime_error(std::string(argv[1]) + ": cannot open");
    const json schema = json::parse(in);
    const json& passes = schema.at("properties").at("passes").at("properties");
    std::filesystem::create_directories(argv[2]);
    // every_technique_params.h: every struct at once, as a type list (tests iterate it, so a new
    // technique is not one more name to add there).
    std::ostringstream every, list;
    every << "#pragma once\n// Generated by radiant_param_structs: every technique's typed parameter struct.\n"
          << "#include <tuple>\n\n";
    for (int i = 3; i < argc; ++i) {
      const std::string technique = argv[i];
      if (!passes.contains(technique)) throw std::runtime_error(technique + ": not in the merged schema");
      const json props = passes[technique].value("properties", json::object());
      writeIfChanged(std::filesystem::path(argv[2]) / (technique + "_params.h"), header(technique, props));
      every << "#include \"params/" << technique << "_params.h\"\n";
      list << (i > 3 ? ",\n                                      " : "") << camel(technique) << "Params";
    }
    every << "\nnamespace radiant {\n\nusing EveryTechniqueParams = std::tuple<" << list.str()
          << ">;\n\n}  // namespace radiant\n";
    writeIfChanged(std::filesystem::path(argv[2]) / "every_technique_params.h", every.str());
  } catch (const std::exception& e) {
    std::cerr << "param_structs: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
