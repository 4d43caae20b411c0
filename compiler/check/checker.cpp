#include "check/checker.h"

#include <algorithm>
#include <array>
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <unistd.h>
#include <cmath>
#include <limits>
#include <functional>
#include <optional>
#include <set>
#include <tuple>
#include <unordered_map>
#include <unordered_set>

#include "check/builtins.h"
#include "check/imports.h"
#include "check/parametric.h"
#include "check/env_map_file.h"
#include "check/image_file.h"
#include "check/other_spellings.h"
#include "check/point_file.h"
#include "shapes/polygon.h"
#include "meshin/mesh_check.h"

namespace sdfc {
namespace {

using glm::dvec3;
using ir::Scalar;

// A checked value. Errors propagate as Type::Error without further messages.
struct Value {
  enum class Type { Error, Number, Vector, Shape, Profile, Material, Field } type = Type::Error;
  Scalar number;
  std::vector<Scalar> vector;
  ir::NodeRef shape;
  int material = -1;
  std::shared_ptr<const ir::ColorField> field;
  SourceRange range;
};

const char* typeName(Value::Type t) {
  switch (t) {
    case Value::Type::Number: return "a number";
    case Value::Type::Vector: return "a vector";
    case Value::Type::Shape: return "a shape";
    case Value::Type::Profile: return "a 2D profile (only extrude and revolve take one)";
    case Value::Type::Material: return "a material";
    case Value::Type::Field: return "a colour field";
    case Value::Type::Error: return "an error";
  }
  return "a value";
}

std::string fmt(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}

struct Binding {
  const ast::Statement* statement = nullptr;
  enum class State { Unresolved, Resolving, Done } state = State::Unresolved;
  Value value;
  bool used = false;
  // A parametric definition: how its body uses each parameter, and one
  // value per distinct argument list (calls with equal arguments share it).
  bool parametric() const { return statement->has_params; }
  std::vector<ParamUsage> uses;
  std::unordered_map<std::string, Value> specialisations;
  bool broken = false;  // it calls itself: reported once, then every call is an error value
  // Imported: the namespace its body looks names up in ("parts." for a file
  // imported `as parts`), and how it came in.
  bool imported = false;
  std::string prefix;
  std::string via;
  // -D NAME=value given for it (NAME as spelt on the command line: "l.q"
  // for a number of a file imported `as l`).
  std::optional<double> define;
  std::string define_name;
};

// What a parameter's use accepts.
bool fitsUse(Value::Type t, ParamUse use) {
  switch (use) {
    case ParamUse::Unknown: return true;
    case ParamUse::Number: return t == Value::Type::Number;
    case ParamUse::Numeric: return t == Value::Type::Number || t == Value::Type::Vector;
    case ParamUse::Vector: return t == Value::Type::Vector;
    case ParamUse::Shape: return t == Value::Type::Shape || t == Value::Type::Profile;
    case ParamUse::Material: return t == Value::Type::Material;
  }
  return true;
}

bool contains(const SourceRange& outer, const SourceRange& inner) {
  return outer.file && inner.file == outer.file && inner.begin >= outer.begin && inner.end <= outer.end;
}

class Checker {
 public:
  Checker(const SourceFile& source, Diagnostics& diags, const CheckOptions& options)
      : source_(source), diags_(&diags), root_diags_(&diags), options_(options) {}

  ir::Scene run(const ast::File& file) {
    imports_ = loadImports(file, source_, *diags_);
    // Pass 1: collect definitions, so they may be used before they appear.
    for (const ast::Statement& s : file.statements) {
      if (!s.is_let) continue;
      if (isReservedName(s.name)) {
        diags_->error(s.name_range, "'" + s.name + "' is a built-in name and cannot be redefined");
        continue;
      }
      auto [it, inserted] = bindings_.try_emplace(s.name);
      if (!inserted) {
        Diagnostic& d = diags_->error(s.name_range, "'" + s.name + "' is already defined");
        d.notes.push_back({Severity::Note, it->second.statement->name_range,
                           "previous definition is here", {}});
        continue;
      }
      it->second.statement = &s;
      order_.push_back(s.name);
      if (s.has_params) checkParameters(s, it->second);
    }
    for (const ImportedDefinition& d : imports_.definitions) bindImported(d);
    for (const ImportAlias& a : imports_.alias_list) checkAliasClashes(a);
    // -D finds its definition as the scene's names do, imported ones too
    // (`-D l.q=3` was accepted and ignored for `import "lib.sdf" as l`).
    for (const auto& [name, value] : options_.defines) {
      Binding* b = findBinding(name);
      if (!b) {
        diags_->error({}, "-D " + name + ": the scene defines no 'let " + name + "'");
      } else if (b->parametric()) {
        diags_->error({}, "-D " + name + ": '" + name + "' is a parametric definition, not a number");
      } else if (b->define) {
        diags_->error({}, "-D " + name + ": '" + b->define_name + "' names the same definition");
      } else {
        b->define = value;
        b->define_name = name;
      }
    }
    // Pass 2: the settings and the scene, in file order.
    bool have_scene = false;
    for (const ast::Statement& s : file.statements) {
      if (s.is_let || !s.value || s.value->kind == ast::ExprKind::Error) continue;
      const ast::Expr& e = *s.value;
      if (e.kind != ast::ExprKind::Call) {
        diags_->error(e.range, "a statement must be 'let', 'scene { ... }' or a setting such as "
                              "'camera(...)'");
        continue;
      }
      if (e.name == "scene") {
        if (have_scene) {
          diags_->error(e.name_range, "the file already has a scene");
          continue;
        }
        have_scene = true;
        checkScene(e);
      } else if (isSettingName(e.name)) {
        checkSetting(e);
      } else {
        Value v = evalExpr(e);
        if (v.type != Value::Type::Error)
          diags_->error(e.range, std::string("a statement cannot be ") + reported(v) +
                                    " on its own; did you mean to put it in 'scene { ... }' or "
                                    "bind it with 'let'?");
      }
    }
    if (!have_scene && !diags_->hasErrors())
      diags_->error({&source_, source_.text.size(), source_.text.size()},
                   "the file has no 'scene { ... }'");
    // Definitions nobody used are still checked, all of them first (one
    // checked later may use an earlier one), then reported. Not after the
    // depth limit stopped a chain: what lies beyond it was never reached, not
    // unused (a chain 5,000 deep gave 4,799 false warnings).
    for (const std::string& name : order_) {
      Binding& b = bindings_[name];
      if (!b.parametric() && !(b.imported && !b.used) && b.state == Binding::State::Unresolved) resolve(name, b);
    }
    for (const std::string& name : depth_exceeded_ ? std::vector<std::string>() : order_) {
      Binding& b = bindings_[name];
      if (b.parametric()) {
        // Its body is checked at each call, with the call's arguments.
        if (!b.used && !b.imported) diags_->warning(b.statement->name_range, "unused", "'" + name + "' is never used");
        continue;
      }
      if (b.imported && !b.used) continue;  // a library's unused parts are not checked here
      if (b.state == Binding::State::Unresolved) resolve(name, b);
      // An unused material gets its own warning below.
      // A definition with errors has been reported already: one mistake, one message.
      if (!b.used && !b.imported && b.value.type != Value::Type::Material && b.value.type != Value::Type::Error)
        diags_->warning(b.statement->name_range, "unused", "'" + name + "' is never used");
    }
    scene_.imported_sources = imports_.files;
    firstMaterialFirst();
    for (size_t i = 0; i < scene_.materials.size(); ++i)
      if (!material_used_[i] && !fromImport(scene_.materials[i].range))
        diags_->warning(scene_.materials[i].range, "unused",
                       "material '" + scene_.materials[i].name + "' is never used by a shape");
    return std::move(scene_);
  }

 private:
  const SourceFile& source_;
  Diagnostics* diags_;  // while a body is expanded: its own list (see expandBody)
  Diagnostics* root_diags_;
  const CheckOptions& options_;
  std::unordered_map<std::string, Binding> bindings_;
  std::vector<std::string> order_;
  ir::Scene scene_;
  std::vector<bool> material_used_;
  std::set<std::string> seen_settings_;
  ImportSet imports_;
  // The namespace names are looked up in: "" in the checked file, "parts."
  // inside the body of a definition imported `as parts`.
  std::string prefix_;

  bool fromImport(const SourceRange& r) const { return r.file && r.file != &source_; }

  // A shape with no material anywhere above it renders with material 0 (the
  // shader's sdMaterial falls through to it, eval and the layers report it),
  // which docs/language.md calls the first material defined in the file, and
  // the layers' material ids count in the file's order. Materials are
  // numbered as they are checked, and a `let` is checked at its first use:
  // they are renumbered here in the order the file writes them (imported
  // ones after, as checked; a file's second material, used first, was the
  // default).
  void firstMaterialFirst() {
    const size_t n = scene_.materials.size();
    std::vector<size_t> order(n);
    for (size_t i = 0; i < n; ++i) order[i] = i;
    std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) {
      const SourceRange &ra = scene_.materials[a].range, &rb = scene_.materials[b].range;
      const bool ha = ra.file == &source_, hb = rb.file == &source_;
      if (ha != hb) return ha;
      return ha && ra.begin < rb.begin;
    });
    std::vector<int> renumbered_as(n);
    bool moved = false;
    for (size_t i = 0; i < n; ++i) {
      renumbered_as[order[i]] = int(i);
      moved = moved || order[i] != i;
    }
    auto renumber = [&](int m) { return m < 0 ? m : renumbered_as[size_t(m)]; };
    if (moved) {
      std::vector<ir::Material> materials;
      std::vector<bool> used;
      for (size_t i : order) {
        materials.push_back(std::move(scene_.materials[i]));
        used.push_back(material_used_[i]);
      }
      scene_.materials = std::move(materials);
      material_used_ = std::move(used);
    }
    const int first = moved ? 1 : 0;  // (the walk renumbers only when something moved)
    if (!scene_.root) return;
    // One visit per (node, material passed down); renumbered once per node.
    std::set<const ir::Node*> renumbered;
    std::set<const ir::InstanceSet*> sets;
    std::set<std::pair<const ir::Node*, int>> seen;
    bool unassigned = false;
    std::function<void(ir::Node&, int)> walk = [&](ir::Node& n, int inherited) {
      if (renumbered.insert(&n).second && first) {
        n.material = renumber(n.material);
        if (n.instances && sets.insert(n.instances.get()).second)
          for (ir::Instance& i : n.instances->instances) i.material = renumber(i.material);
      }
      const int m = n.material >= 0 ? n.material : inherited;
      if (!seen.insert({&n, m}).second) return;
      if (n.kind == ir::NodeKind::Primitive && m < 0) unassigned = true;
      for (const ir::NodeRef& c : n.children) walk(*c, m);
    };
    walk(*scene_.root, -1);
    // The default material is used by the shapes that have none.
    if (unassigned && !material_used_.empty()) material_used_[0] = true;
  }

  // The file whose names are being looked up (with prefix_): the checked
  // file, or the one holding the definition being resolved or expanded.
  const SourceFile* file_ = &source_;
  std::map<std::pair<const SourceFile*, const SourceFile*>, bool> visible_;

  // Whether a body in `from` may use a definition of `to`: the same file or
  // one `from` imports, transitively (an imported file does not see the
  // names of the file importing it, nor of its siblings).
  bool sees(const SourceFile* from, const SourceFile* to) {
    if (from == to) return true;
    auto [it, inserted] = visible_.try_emplace({from, to}, false);
    if (!inserted) return it->second;
    auto edges = imports_.edges.find(from);
    bool found = false;
    if (edges != imports_.edges.end())
      for (const SourceFile* next : edges->second) found = found || sees(next, to);
    visible_[{from, to}] = found;
    return found;
  }

  // The binding `name` (qualified by prefix_) as seen from file_, or null.
  Binding* findBinding(const std::string& name) {
    auto visible = [&](const std::string& key) {
      auto it = bindings_.find(key);
      return it != bindings_.end() && sees(file_, it->second.statement->name_range.file);
    };
    const std::string key = resolveImportedKey(imports_.aliases, prefix_ + name, prefix_.size(), visible);
    if (!key.empty()) return &bindings_[key];
    auto it = bindings_.find(hiddenKey(file_, prefix_ + name));
    return it != bindings_.end() ? &it->second : nullptr;
  }
  // The nearest spelling of the qualified `name` ("p.rok": "p.rook") among
  // the definitions under its namespace, as this body sees them; "" if none.
  std::string nearestQualified(const std::string& name) {
    const size_t dot = name.rfind('.');
    const std::string space = prefix_ + name.substr(0, dot + 1);
    std::vector<std::string> spaces = {space};
    if (auto a = imports_.aliases.find(space); a != imports_.aliases.end())
      spaces.insert(spaces.end(), a->second.begin(), a->second.end());
    std::vector<std::string> candidates;
    for (const std::string& s : spaces)
      for (const std::string& key : order_)
        if (key.compare(0, s.size(), s) == 0 && key.find('.', s.size()) == std::string::npos &&
            findBinding(name.substr(0, dot + 1) + key.substr(s.size())))
          candidates.push_back(key.substr(s.size()));
    const std::string near = nearestName(name.substr(dot + 1), candidates);
    return near.empty() ? "" : name.substr(0, dot + 1) + near;
  }

  // Where a definition that lost a clash is bound: its own file still sees it.
  static std::string hiddenKey(const SourceFile* file, const std::string& key) {
    return "#" + (file ? file->path : std::string()) + "#" + key;
  }

  void bindImported(const ImportedDefinition& d) {
    const ast::Statement& s = *d.statement;
    const std::string key = d.prefix + s.name;
    if (isReservedName(s.name)) {
      diags_->error(s.name_range, "'" + s.name + "' is a built-in name and cannot be redefined");
      return;
    }
    auto [it, inserted] = bindings_.try_emplace(key);
    if (!inserted) {
      const Binding& old = it->second;
      Diagnostic& e = diags_->error(d.import->import_path_range,
                                    "this import brings in '" + key + "', which is already defined");
      e.notes.push_back({Severity::Note, s.name_range, "'" + s.name + "' from " + d.via + " is defined here", {}});
      e.notes.push_back({Severity::Note, old.statement->name_range,
                         "'" + key + "' " + (old.imported ? "from " + old.via + " " : "") + "is defined here", {}});
      it = bindings_.try_emplace(hiddenKey(s.name_range.file, key)).first;
      if (it->second.statement) return;
    }
    Binding& b = it->second;
    b.statement = &s;
    b.imported = true;
    b.prefix = d.prefix;
    b.via = d.via;
    order_.push_back(it->first);
    if (s.has_params) checkParameters(s, b);
  }
  // A file bound once and reached again (imports.h) brings its names in
  // under another prefix too: a clash there is the error binding it twice
  // under that prefix gave.
  void checkAliasClashes(const ImportAlias& a) {
    for (const std::string& key : order_) {
      if (key.compare(0, a.to.size(), a.to) != 0 || key.find('.', a.to.size()) != std::string::npos) continue;
      const Binding& b = bindings_[key];
      const std::string name = a.from + key.substr(a.to.size());
      auto it = bindings_.find(name);
      if (!b.imported || it == bindings_.end() || it->second.statement == b.statement) continue;
      const Binding& old = it->second;
      Diagnostic& e = diags_->error(a.import->import_path_range,
                                    "this import brings in '" + name + "', which is already defined");
      e.notes.push_back({Severity::Note, b.statement->name_range,
                         "'" + b.statement->name + "' from " + a.via + " is defined here", {}});
      e.notes.push_back({Severity::Note, old.statement->name_range,
                         "'" + name + "' " + (old.imported ? "from " + old.via + " " : "") + "is defined here", {}});
    }
  }

  // The parameters in scope while a parametric body is checked (null at the
  // top level: a body sees its parameters and the file's definitions only).
  const std::unordered_map<std::string, Value>* params_ = nullptr;
  // The calls being expanded, outermost first (for recursion and its chain).
  struct Expansion {
    const Binding* binding;
    SourceRange call;
  };
  std::vector<Expansion> expansions_;
  // Warnings inside a body, reported once however many calls expand it.
  std::set<std::tuple<const SourceFile*, size_t, std::string>> body_warnings_;

  // A value named in a type error: a material there was meant to be used, so
  // it gets no "never used" warning on top (one mistake, one message).
  const char* reported(const Value& v) {
    if (v.type == Value::Type::Material) material_used_[v.material] = true;
    return typeName(v.type);
  }

  // ---- names -------------------------------------------------------------

  // Definitions resolve recursively (a `let` using another resolves it
  // first); a chain deeper than this is reported, not recursed into.
  static constexpr int kMaxDefinitionDepth = 200;
  int resolve_depth_ = 0;
  bool depth_exceeded_ = false;  // reported: the "never used" warnings would be false

  const Value& resolve(const std::string& name, Binding& b) {
    if (b.state == Binding::State::Done) return b.value;
    if (resolve_depth_ >= kMaxDefinitionDepth) {
      depth_exceeded_ = true;
      diags_->error(b.statement->name_range,
                   "definitions refer to each other more than " +
                       std::to_string(kMaxDefinitionDepth) + " levels deep");
      b.state = Binding::State::Done;
      return b.value;
    }
    struct DepthGuard {
      int& depth;
      explicit DepthGuard(int& d) : depth(d) { ++depth; }
      ~DepthGuard() { --depth; }
    } guard(resolve_depth_);
    b.state = Binding::State::Resolving;
    const ast::Statement& s = *b.statement;
    // A definition sees the file's names, never the parameters of a body
    // that happens to use it first.
    const auto* outer_params = params_;
    params_ = nullptr;
    const std::string outer_prefix = prefix_;
    const SourceFile* outer_file = file_;
    prefix_ = b.prefix;
    file_ = s.name_range.file;
    Value v = evalExpr(*s.value);
    prefix_ = outer_prefix;
    file_ = outer_file;
    params_ = outer_params;
    if (b.define) {
      if (v.type != Value::Type::Number && v.type != Value::Type::Error) {
        diags_->error(s.name_range, "-D " + b.define_name + " gives a number, but '" + b.define_name + "' is " +
                                       reported(v));
      } else {
        v.type = Value::Type::Number;
        v.number = ir::constant(*b.define);
      }
    }
    // A named shape becomes a named function in the emitted shader: a GLSL
    // name, so "l.ball" (first used as an imported name) is "l_ball".
    if (v.type == Value::Type::Shape && v.shape->definition.empty()) {
      v.shape->definition = name;
      std::replace(v.shape->definition.begin(), v.shape->definition.end(), '.', '_');
    }
    if (v.type == Value::Type::Material && scene_.materials[v.material].name.empty())
      scene_.materials[v.material].name = name;
    b.value = v;
    b.state = Binding::State::Done;
    return b.value;
  }

  Value lookupName(const ast::Expr& e) {
    if (e.bad_name) return {};  // the lexer reported it
    if (e.name == "time") {
      scene_.uses_time = true;
      return number(ir::timeScalar(), e.range);
    }
    if (e.name == "pi") return number(ir::constant(M_PI), e.range);
    if (params_) {
      auto p = params_->find(e.name);
      if (p != params_->end()) {
        Value v = p->second;
        v.range = e.range;
        return v;
      }
    }
    Binding* found = findBinding(e.name);
    if (!found) {
      std::vector<std::string> candidates;
      for (const std::string& key : order_)
        if (key.compare(0, prefix_.size(), prefix_) == 0) candidates.push_back(key.substr(prefix_.size()));
      if (params_)
        for (const auto& [name, value] : *params_) candidates.push_back(name);
      candidates.push_back("time");
      candidates.push_back("pi");
      std::string message = "unknown name '" + e.name + "'";
      const std::string near = nearestName(e.name, candidates);
      if (!near.empty() && near != e.name) message += "; did you mean '" + near + "'?";
      if (isBuiltinCallable(e.name)) message = "'" + e.name + "' must be called: '" + e.name + "(...)'";
      diags_->error(e.range, message);
      return {};
    }
    Binding& b = *found;
    b.used = true;
    if (b.parametric()) {
      Diagnostic& d = diags_->error(e.range, "'" + e.name + "' has parameters; call it: '" + e.name + "(...)'");
      d.notes.push_back({Severity::Note, b.statement->name_range, "'" + e.name + "' is defined here", {}});
      return {};
    }
    if (b.state == Binding::State::Resolving) {
      Diagnostic& d = diags_->error(e.range, "'" + e.name + "' is defined in terms of itself");
      d.notes.push_back({Severity::Note, b.statement->name_range, "'" + e.name + "' is defined here", {}});
      return {};
    }
    Value v = resolve(e.name, b);
    v.range = e.range;
    return v;
  }

  // ---- expressions -------------------------------------------------------

  static Value number(Scalar s, SourceRange r) {
    Value v;
    v.type = Value::Type::Number;
    v.number = s;
    v.range = r;
    return v;
  }

  Value evalExpr(const ast::Expr& e) {
    switch (e.kind) {
      case ast::ExprKind::Error: return {};
      case ast::ExprKind::Number: return number(ir::constant(e.number), e.range);
      case ast::ExprKind::String:
        diags_->error(e.range, "a string is no value here: strings only name files, as in mesh(file: \"part.stl\"), "
                              "texture(file: ...), sky(map: ...), instances(positions: file(\"points.csv\")) and import");
        return {};
      case ast::ExprKind::Name: return lookupName(e);
      case ast::ExprKind::Vector: {
        if (e.reported) return {};  // the parser reported it
        Value v;
        v.type = Value::Type::Vector;
        v.range = e.range;
        for (const ast::ExprPtr& el : e.operands) {
          Value x = evalExpr(*el);
          if (x.type == Value::Type::Error) return {};
          if (x.type != Value::Type::Number) {
            diags_->error(x.range, std::string("a vector element must be a number, not ") +
                                      reported(x));
            return {};
          }
          v.vector.push_back(x.number);
        }
        if (v.vector.size() > 4) {
          diags_->error(e.range, "vectors have at most 4 elements, this one has " +
                                    std::to_string(v.vector.size()));
          return {};
        }
        return v;
      }
      case ast::ExprKind::Unary: {
        Value a = evalExpr(*e.operands[0]);
        if (a.type == Value::Type::Number) {
          const Scalar r = ir::unary('-', a.number);
          return timeExpressionFits(r, e.range) ? number(r, e.range) : Value{};
        }
        if (a.type == Value::Type::Vector) {
          for (Scalar& s : a.vector) s = ir::unary('-', s);
          a.range = e.range;
          return a;
        }
        if (a.type != Value::Type::Error)
          diags_->error(e.range, std::string("cannot negate ") + reported(a));
        return {};
      }
      case ast::ExprKind::Binary: return evalBinary(e);
      case ast::ExprKind::Member: {
        // `parts.stone`: a definition imported `as parts`.
        const ast::Expr& o = *e.operands[0];
        const bool alias = o.kind == ast::ExprKind::Name && !(params_ && params_->count(o.name)) && !findBinding(o.name);
        // `parts.rok`: a misspelt imported name, said as one.
        if (alias && !findBinding(o.name + "." + e.name)) {
          if (const std::string near = nearestQualified(o.name + "." + e.name); !near.empty()) {
            diags_->error(e.range, "unknown name '" + o.name + "." + e.name + "'; did you mean '" + near + "'?");
            return {};
          }
        }
        if (alias && findBinding(o.name + "." + e.name)) {
          ast::Expr qualified;
          qualified.kind = ast::ExprKind::Name;
          qualified.name = o.name + "." + e.name;
          qualified.range = e.range;
          return lookupName(qualified);
        }
        Value a = evalExpr(*e.operands[0]);
        if (a.type == Value::Type::Error) return {};
        static const std::string kFields = "xyzw";
        const size_t index = e.name.size() == 1 ? kFields.find(e.name[0]) : std::string::npos;
        if (a.type != Value::Type::Vector || index == std::string::npos ||
            index >= a.vector.size()) {
          diags_->error(e.name_range, "no component '" + e.name + "' in " + reported(a));
          return {};
        }
        return number(a.vector[index], e.range);
      }
      case ast::ExprKind::Call: return evalCall(e);
    }
    return {};
  }

  Value evalBinary(const ast::Expr& e) {
    Value a = evalExpr(*e.operands[0]);
    Value b = evalExpr(*e.operands[1]);
    if (a.type == Value::Type::Error || b.type == Value::Type::Error) return {};
    const char op = e.op;
    auto scalarOp = [&](const Scalar& x, const Scalar& y) -> std::optional<Scalar> {
      if (op == '/' && y.isConst() && y.value == 0) {
        diags_->error(e.operands[1]->range, "division by zero");
        return std::nullopt;
      }
      Scalar r = ir::binary(op, x, y);
      if (r.isConst() && !std::isfinite(r.value)) {
        diags_->error(e.range, "this arithmetic overflows to a value that is not finite");
        return std::nullopt;
      }
      if (!timeExpressionFits(r, e.range)) return std::nullopt;
      if (op == '/' && !y.isConst()) {
        const ir::Interval d = y.range();
        if (d.lo == 0 && d.hi == 0) {
          diags_->error(e.operands[1]->range, "division by zero at every time");
          return std::nullopt;
        }
        if (d.lo <= 0 && d.hi >= 0)
          diags_->warning(e.operands[1]->range, "time-range", "the divisor ranges over " + rangeText(d) +
                                                   " over time; where it is 0 the value is not finite");
      }
      return r;
    };
    if (a.type == Value::Type::Number && b.type == Value::Type::Number) {
      auto r = scalarOp(a.number, b.number);
      return r ? number(*r, e.range) : Value{};
    }
    // Vector with vector (same size, component-wise) or with a number.
    const bool va = a.type == Value::Type::Vector, vb = b.type == Value::Type::Vector;
    const bool na = a.type == Value::Type::Number, nb = b.type == Value::Type::Number;
    if ((va && (vb || nb)) || (na && vb)) {
      if (va && vb && a.vector.size() != b.vector.size()) {
        diags_->error(e.range, "vectors of different sizes (" + std::to_string(a.vector.size()) +
                                  " and " + std::to_string(b.vector.size()) + ")");
        return {};
      }
      const size_t n = va ? a.vector.size() : b.vector.size();
      Value v;
      v.type = Value::Type::Vector;
      v.range = e.range;
      for (size_t i = 0; i < n; ++i) {
        auto r = scalarOp(va ? a.vector[i] : a.number, vb ? b.vector[i] : b.number);
        if (!r) return {};
        v.vector.push_back(*r);
      }
      return v;
    }
    diags_->error(e.range, std::string("cannot apply '") + op + "' to " + reported(a) +
                              " and " + reported(b));
    return {};
  }

  // ---- calls -------------------------------------------------------------

  Value evalCall(const ast::Expr& e) {
    if (e.bad_name) return {};  // the lexer reported it
    if (e.name == "file") {
      diags_->error(e.name_range, "'file' may only give the positions of instances(...)");
      return {};
    }
    if (params_ && params_->count(e.name)) {
      diags_->error(e.name_range, "'" + e.name + "' is a parameter, not a definition: it cannot be called");
      return {};
    }
    if (Binding* b = findBinding(e.name)) {
      if (b->parametric()) return evalDefinitionCall(e, *b);
      b->used = true;
      Diagnostic& d = diags_->error(e.name_range, "'" + e.name + "' has no parameters; use it without '(...)'");
      d.notes.push_back({Severity::Note, b->statement->name_range, "'" + e.name + "' is defined here", {}});
      return {};
    }
    if (e.name == "instances") return evalInstances(e, *findBuiltin("instances"));
    if (e.name == "mesh") return evalMesh(e);
    if (const int arity = ir::mathFunctionArity(e.name); arity >= 0) return evalMath(e, arity);
    if (const PrimitiveInfo* prim = findPrimitive(e.name)) return evalPrimitive(e, *prim);
    if (const BuiltinSignature* sig = findBuiltin(e.name)) {
      switch (sig->category) {
        case BuiltinCategory::Operator: return evalOperator(e, *sig);
        case BuiltinCategory::Material: return evalMaterial(e, *sig);
        case BuiltinCategory::Field: return evalField(e, *sig);
        case BuiltinCategory::Setting:
          diags_->error(e.name_range, "'" + e.name + "' is a setting; write it as a statement on "
                                                    "its own line");
          return {};
      }
    }
    if (e.name == "scene") {
      diags_->error(e.name_range, "'scene' must be a statement on its own");
      return {};
    }
    if (e.name.find('.') != std::string::npos) {
      const std::string near = nearestQualified(e.name);
      diags_->error(e.name_range, "unknown definition '" + e.name + "'" +
                                      (near.empty() ? " (an imported one is 'alias.name', for import \"file.sdf\" as alias)"
                                                    : "; did you mean '" + near + "'?"));
      return {};
    }
    std::string message = "unknown function '" + e.name + "'";
    const std::string other = otherToolSpelling(e.name);
    const std::string near = nearestName(e.name, allCallableNames());
    if (!other.empty()) message += "; sdfc writes this as '" + other + "'";
    else if (!near.empty()) message += "; did you mean '" + near + "'?";
    diags_->error(e.name_range, message);
    return {};
  }

  // ---- parametric definitions --------------------------------------------

  void checkParameters(const ast::Statement& s, Binding& b) {
    std::set<std::string> seen;
    for (const ast::Parameter& p : s.params) {
      if (isReservedName(p.name)) {
        diags_->error(p.name_range, "'" + p.name + "' is a built-in name and cannot be a parameter");
        b.broken = true;
      } else if (!seen.insert(p.name).second) {
        diags_->error(p.name_range, "'" + s.name + "' has two parameters named '" + p.name + "'");
        b.broken = true;
      }
    }
    b.uses = inferParameterUses(s);
  }

  // Equal keys: equal arguments (shapes and materials by identity).
  static std::string valueKey(const Value& v) {
    char buf[48];
    switch (v.type) {
      case Value::Type::Number: return "n" + scalarKey(v.number);
      case Value::Type::Vector: {
        std::string k = "v";
        for (const Scalar& s : v.vector) k += scalarKey(s) + ",";
        return k;
      }
      case Value::Type::Shape:
      case Value::Type::Profile: std::snprintf(buf, sizeof buf, "s%p", static_cast<const void*>(v.shape.get())); return buf;
      case Value::Type::Material: return "m" + std::to_string(v.material);
      case Value::Type::Field: std::snprintf(buf, sizeof buf, "f%p", static_cast<const void*>(v.field.get())); return buf;
      case Value::Type::Error: return "e";
    }
    return "?";
  }

  // A call of `let name(params) = body`: the arguments are bound in the
  // caller's scope, checked against how the body uses them, and the body is
  // checked with them (once per distinct argument list). The result is the
  // shape (or value) written out: every later stage sees no difference.
  Value evalDefinitionCall(const ast::Expr& e, Binding& b) {
    b.used = true;
    const ast::Statement& def = *b.statement;
    const std::string& name = def.name;
    auto definedHere = [&](Diagnostic& d) {
      d.notes.push_back({Severity::Note, def.name_range, "'" + name + "' is defined here", {}});
    };
    if (b.broken) return {};
    for (size_t i = 0; i < expansions_.size(); ++i) {
      if (expansions_[i].binding != &b) continue;
      std::string chain;
      for (size_t j = i; j < expansions_.size(); ++j) chain += "'" + expansions_[j].binding->statement->name + "' -> ";
      chain += "'" + name + "'";
      Diagnostic d{Severity::Error, e.name_range,
                   "'" + name + "' calls itself (" + chain + "); recursion is not allowed, nothing could end it", {}};
      for (size_t j = i + 1; j < expansions_.size(); ++j)
        d.notes.push_back({Severity::Note, expansions_[j].call,
                           "'" + expansions_[j].binding->statement->name + "' is called here", {}});
      definedHere(d);
      root_diags_->add(std::move(d));  // once, as it is, not as an error of the outer call
      b.broken = true;
      return {};
    }
    if (e.has_block) {
      Diagnostic& d = diags_->error(e.range, "'" + name + "' is a definition and takes no block; pass shapes "
                                             "as arguments");
      definedHere(d);
      return {};
    }
    const size_t n = def.params.size();
    std::vector<std::optional<Value>> values(n);
    bool ok = true;
    size_t next_positional = 0;
    bool seen_named = false;
    for (const ast::Argument& a : e.arguments) {
      Value v = evalExpr(*a.value);
      if (v.type == Value::Type::Error) {
        ok = false;
        continue;
      }
      size_t index = n;
      if (a.name.empty()) {
        if (seen_named) {
          diags_->error(a.value->range, "positional argument after a named one");
          ok = false;
          continue;
        }
        if (next_positional >= n) {
          Diagnostic& d = diags_->error(a.value->range, "'" + name + "' takes at most " + std::to_string(n) +
                                                            " positional argument" + (n == 1 ? "" : "s"));
          definedHere(d);
          ok = false;
          continue;
        }
        index = next_positional++;
      } else {
        seen_named = true;
        for (size_t i = 0; i < n; ++i)
          if (def.params[i].name == a.name) index = i;
        if (index == n) {
          std::vector<std::string> names;
          for (const ast::Parameter& p : def.params) names.push_back(p.name);
          std::string message = "'" + name + "' has no parameter '" + a.name + "'";
          const std::string near = nearestName(a.name, names);
          if (!near.empty()) message += "; did you mean '" + near + "'?";
          Diagnostic& d = diags_->error(a.name_range, message);
          definedHere(d);
          ok = false;
          continue;
        }
        if (values[index]) {
          diags_->error(a.name_range, "'" + a.name + "' is given twice");
          ok = false;
          continue;
        }
      }
      const ParamUsage& use = b.uses[index];
      if (!fitsUse(v.type, use.use)) {
        Diagnostic& d = diags_->error(v.range, "'" + def.params[index].name + "' of '" + name + "' must be " +
                                                   paramUseName(use.use) + ", not " + typeName(v.type));
        d.notes.push_back({Severity::Note, use.where,
                           "'" + name + "' uses '" + def.params[index].name + "' as " + paramUseName(use.use) + " here", {}});
        ok = false;
        continue;
      }
      values[index] = v;
    }
    for (size_t i = 0; i < n && ok; ++i) {
      if (values[i] || def.params[i].default_value) continue;
      Diagnostic& d = diags_->error(e.range, "'" + name + "' needs '" + def.params[i].name + "'");
      d.notes.push_back({Severity::Note, def.params[i].name_range,
                         "'" + def.params[i].name + "' has no default", {}});
      ok = false;
    }
    if (!ok) return {};
    // Defaults depend only on earlier parameters: the given ones are the key.
    std::string key;
    for (const std::optional<Value>& v : values) key += (v ? valueKey(*v) : std::string("default")) + ";";
    auto memo = b.specialisations.find(key);
    if (memo != b.specialisations.end()) {
      Value v = memo->second;
      v.range = e.range;
      return v;
    }
    if (resolve_depth_ >= kMaxDefinitionDepth) {
      depth_exceeded_ = true;
      diags_->error(e.range, "definitions call each other more than " + std::to_string(kMaxDefinitionDepth) +
                                 " levels deep");
      return {};
    }
    Value result = expandBody(e, b, values);
    if (result.type == Value::Type::Shape && result.shape->definition.empty() &&
        result.shape->kind != ir::NodeKind::Primitive)
      result.shape->definition = name;  // one function per specialisation (a lone primitive stays inline)
    if (result.type == Value::Type::Material && scene_.materials[result.material].name.empty())
      scene_.materials[result.material].name = name;
    b.specialisations.emplace(key, result);
    result.range = e.range;
    return result;
  }

  // Checks the body of `b` with its parameters bound. Problems inside the
  // definition become errors at the call (the chain of calls shows in the
  // message), each with a note where in the definition it arose.
  Value expandBody(const ast::Expr& call, Binding& b, const std::vector<std::optional<Value>>& values) {
    const ast::Statement& def = *b.statement;
    Diagnostics captured;
    Diagnostics* const outer_diags = diags_;
    const auto* outer_params = params_;
    std::unordered_map<std::string, Value> scope;
    diags_ = &captured;
    params_ = &scope;
    const std::string outer_prefix = prefix_;
    const SourceFile* outer_file = file_;
    prefix_ = b.prefix;
    file_ = def.name_range.file;
    expansions_.push_back({&b, call.range});
    ++resolve_depth_;
    bool ok = true;
    for (size_t i = 0; i < def.params.size() && ok; ++i) {
      Value v = values[i] ? *values[i] : evalExpr(*def.params[i].default_value);
      if (v.type == Value::Type::Error) ok = false;
      scope[def.params[i].name] = v;
    }
    Value result = ok ? evalExpr(*def.value) : Value{};
    --resolve_depth_;
    expansions_.pop_back();
    params_ = outer_params;
    prefix_ = outer_prefix;
    file_ = outer_file;
    diags_ = outer_diags;
    for (const Diagnostic& d : captured.all()) {
      if (!contains(def.range, d.range)) {
        diags_->add(d);
      } else if (d.severity == Severity::Error) {
        Diagnostic wrapped{Severity::Error, call.range, "in this call of '" + call.name + "': " + d.message, {}};
        wrapped.notes.push_back({Severity::Note, d.range, "here, in the definition of '" + def.name + "'", {}});
        for (const Diagnostic& note : d.notes) wrapped.notes.push_back(note);
        diags_->add(std::move(wrapped));
      } else if (body_warnings_.insert({d.range.file, d.range.begin, d.message}).second) {
        diags_->add(d);
      }
    }
    if (captured.hasErrors()) return {};
    return result;
  }

  Value evalMath(const ast::Expr& e, int arity) {
    if (e.has_block) diags_->error(e.range, "'" + e.name + "' takes no block");
    std::vector<Scalar> args;
    for (const ast::Argument& a : e.arguments) {
      if (!a.name.empty()) diags_->error(a.name_range, "'" + e.name + "' takes positional arguments");
      Value v = evalExpr(*a.value);
      if (v.type == Value::Type::Error) return {};
      if (v.type != Value::Type::Number) {
        diags_->error(v.range, "'" + e.name + "' expects numbers, not " + reported(v));
        return {};
      }
      args.push_back(v.number);
    }
    if (static_cast<int>(args.size()) != arity) {
      diags_->error(e.range, "'" + e.name + "' takes " + std::to_string(arity) + " argument" +
                                (arity == 1 ? "" : "s") + ", got " + std::to_string(args.size()));
      return {};
    }
    Scalar r = ir::callFunction(e.name, args);
    if (r.isConst() && !std::isfinite(r.value)) {
      diags_->error(e.range, "'" + e.name + "' gives a value that is not finite here");
      return {};
    }
    if (!r.isConst() && (!timeExpressionFits(r, e.range) || !checkDomainOverTime(e, args)))
      return {};
    return number(r, e.range);
  }

  // ---- values the shader computes in float32 ------------------------------

  static std::string rangeText(const ir::Interval& r) { return "[" + fmt(r.lo) + ", " + fmt(r.hi) + "]"; }

  // A time-dependent expression is written out whole into the shader (and
  // walked by interval arithmetic): its size is limited.
  bool timeExpressionFits(const Scalar& s, const SourceRange& range) {
    if (s.isConst() || s.expr->size <= kMaxTimeExpressionSize) return true;
    diags_->error(range, "this expression depends on 'time' and would be " + fmt(s.expr->size) +
                            " operations in the shader; at most " + std::to_string(kMaxTimeExpressionSize) +
                            " (name a part with 'let' only shares it in the checker, not in the shader)");
    return false;
  }

  // Functions undefined (or overflowing float32) for part of their domain,
  // over the argument's range across all times: never defined is an error,
  // sometimes a warning that names the range.
  bool checkDomainOverTime(const ast::Expr& e, const std::vector<Scalar>& args) {
    auto report = [&](bool never, const std::string& what) {
      if (never) {
        diags_->error(e.range, "'" + e.name + "' is not finite at any time: " + what);
        return false;
      }
      diags_->warning(e.range, "time-range", "'" + e.name + "' is not finite for some times: " + what);
      return true;
    };
    if (e.name == "sqrt") {
      const ir::Interval a = args[0].range();
      if (a.lo < 0) return report(a.hi < 0, "its argument ranges over " + rangeText(a) +
                                                " and is negative there");
    } else if (e.name == "exp") {
      const double limit = std::log(static_cast<double>(std::numeric_limits<float>::max()));
      const ir::Interval a = args[0].range();
      if (a.hi > limit)
        return report(a.lo > limit, "its argument ranges over " + rangeText(a) + ", and above " +
                                        fmt(limit) + " the result overflows float32");
    } else if (e.name == "pow") {
      const ir::Interval a = args[0].range();
      const bool whole_exponent = args[1].isConst() && args[1].value == std::floor(args[1].value);
      if (a.lo < 0 && !whole_exponent)
        return report(a.hi < 0, "its base ranges over " + rangeText(a) +
                                    " and a negative base needs a whole exponent");
    }
    return true;
  }

  // Every number the shader receives must be a float32: a constant beyond
  // its range is an error (translate by 1e39 would be infinite in the
  // shader); a time-dependent value outside it at every time is an error,
  // at some times a warning naming its range.
  bool checkShaderValue(const Scalar& s, const SourceRange& range, const std::string& what) {
    constexpr double kFloatMax = std::numeric_limits<float>::max();
    const double largest = ir::largestConstant(s);
    if (largest > kFloatMax) {
      diags_->error(range, what + (s.isConst() ? " is " : " uses the constant ") + fmt(s.isConst() ? s.value : largest) +
                              ", beyond the range of the shader's float32 numbers (" + fmt(kFloatMax) + ")");
      return false;
    }
    if (s.isConst()) return true;
    const ir::Interval r = s.range();
    if (!r.bounded()) return true;  // grows with time without bound: fine at any one time
    if (r.lo > kFloatMax || r.hi < -kFloatMax) {
      diags_->error(range, what + " ranges over " + rangeText(r) +
                              " over time, beyond the range of the shader's float32 numbers");
      return false;
    }
    if (r.hi > kFloatMax || r.lo < -kFloatMax)
      diags_->warning(range, "time-range", what + " ranges over " + rangeText(r) +
                                " over time; where it is beyond " + fmt(kFloatMax) +
                                " the shader's float32 value is infinite");
    return true;
  }

  // Matches call arguments to a parameter list: positional in order, then
  // named. Unknown names get a suggestion; missing required ones an error.
  // `material` is accepted wherever `allow_material` is set.
  struct BoundArgs {
    std::vector<std::optional<Value>> values;
    std::optional<Value> material;
    bool ok = true;
    // The argument named file_param, its string read from the syntax (a file
    // name is no value of the language): sky(map: "studio.exr").
    const ast::Argument* file = nullptr;
  };

  BoundArgs bindArguments(const ast::Expr& e, const std::vector<ArgSpec>& specs,
                          bool allow_material, const char* file_param = nullptr) {
    BoundArgs out;
    out.values.resize(specs.size());
    size_t next_positional = 0;
    bool seen_named = false;
    size_t extra_positional = 0;
    const ast::Argument* first_extra = nullptr;
    for (const ast::Argument& a : e.arguments) {
      if (file_param && a.name == file_param) {
        seen_named = true;
        if (out.file) {
          diags_->error(a.name_range, "'" + a.name + "' is given twice");
          out.ok = false;
        }
        out.file = &a;
        continue;
      }
      // A string given to a name that is no parameter (sky(mop: "x.exr")):
      // the error is the name, with a suggestion, not the string.
      bool unknown_name = !a.name.empty() && a.name != "material";
      for (const ArgSpec& spec : specs) unknown_name = unknown_name && a.name != spec.name;
      // A string for a parameter that takes a value: say what it takes.
      const ArgSpec* spec = nullptr;
      if (a.value->kind == ast::ExprKind::String) {
        if (a.name.empty() && !seen_named && next_positional < specs.size()) spec = &specs[next_positional];
        for (const ArgSpec& s : specs)
          if (!a.name.empty() && a.name == s.name) spec = &s;
      }
      if (spec && spec->type != ArgType::Any) {
        diags_->error(a.value->range, "'" + std::string(spec->name) + "' of '" + e.name + "' must be " +
                                          argTypeText(spec->type) +
                                          ", not a string (a string names a file, as in mesh(file: \"part.stl\"))");
        out.ok = false;
        if (a.name.empty()) ++next_positional;
        else seen_named = true;
        continue;
      }
      Value v = file_param && unknown_name && a.value->kind == ast::ExprKind::String
                    ? number(ir::constant(0), a.value->range)
                    : evalExpr(*a.value);
      // A material given to a call with errors was still meant for it: no
      // "never used" warning on top of the error.
      if (a.name == "material" && v.type == Value::Type::Material) material_used_[v.material] = true;
      if (v.type == Value::Type::Error) {
        out.ok = false;
        continue;
      }
      if (a.name.empty()) {
        if (seen_named) {
          diags_->error(a.value->range, "positional argument after a named one");
          out.ok = false;
          continue;
        }
        if (next_positional >= specs.size()) {
          // One error for all the extra ones, at the first.
          if (extra_positional++ == 0) first_extra = &a;
          out.ok = false;
          continue;
        }
        out.values[next_positional++] = v;
        continue;
      }
      seen_named = true;
      if (allow_material && a.name == "material") {
        if (out.material) diags_->error(a.name_range, "'material' is given twice");
        out.material = v;
        continue;
      }
      size_t index = specs.size();
      for (size_t i = 0; i < specs.size(); ++i)
        if (a.name == specs[i].name) index = i;
      if (index == specs.size()) {
        std::vector<std::string> names;
        for (const ArgSpec& s : specs) names.push_back(s.name);
        if (allow_material) names.push_back("material");
        std::string message = "'" + e.name + "' has no parameter '" + a.name + "'";
        std::string near = nearestName(a.name, names);
        // Other tools' names for the same parameter (a new user's chess set
        // wrote rotate(angle: 90)), where spelling distance finds nothing.
        static const std::pair<const char*, const char*> kOtherNames[] = {
            {"angle", "degrees"}, {"degree", "degrees"}, {"deg", "degrees"}, {"r", "radius"},
            {"dims", "size"},     {"extent", "size"},    {"extents", "size"}, {"color", "albedo"},
            {"colour", "albedo"}};
        for (const auto& [other, ours] : kOtherNames)
          if (near.empty() && a.name == other && std::find(names.begin(), names.end(), ours) != names.end()) near = ours;
        if (!near.empty()) message += "; did you mean '" + near + "'?";
        diags_->error(a.name_range, message);
        out.ok = false;
        continue;
      }
      if (out.values[index]) {
        diags_->error(a.name_range, "'" + a.name + "' is given twice");
        out.ok = false;
        continue;
      }
      out.values[index] = v;
    }
    if (first_extra)
      diags_->error(first_extra->value->range, "'" + e.name + "' takes at most " +
                                                  std::to_string(specs.size()) + " positional argument" +
                                                  (specs.size() == 1 ? "" : "s") + ", got " +
                                                  std::to_string(specs.size() + extra_positional));
    for (size_t i = 0; i < specs.size(); ++i) {
      if (out.values[i] || !specs[i].required) continue;
      if (!out.ok) continue;  // an argument failed: it may have been this one
      diags_->error(e.range, "'" + e.name + "' needs '" + specs[i].name + "'");
      out.ok = false;
    }
    return out;
  }

  static std::string argTypeText(ArgType t) {
    switch (t) {
      case ArgType::Number: return "a number";
      case ArgType::Vector3: return "a 3-vector like [x, y, z]";
      case ArgType::Vector2: return "a 2-vector like [x, y]";
      case ArgType::Colour: return "a colour like [r, g, b] (or a colour field)";
      case ArgType::Any: break;
    }
    return "a value";
  }

  // Converts and validates one argument against its spec.
  std::optional<ir::Vec3> asVec3(const Value& v, const ArgSpec& spec, const std::string& callee) {
    if (v.type == Value::Type::Number && (spec.type == ArgType::Vector3 || spec.type == ArgType::Colour)) {
      return ir::Vec3{v.number, v.number, v.number};  // a number stands for a uniform vector
    }
    if (v.type != Value::Type::Vector || (v.vector.size() != 3)) {
      diags_->error(v.range, "'" + std::string(spec.name) + "' of '" + callee +
                                "' must be a 3-vector like [x, y, z], not " +
                                (v.type == Value::Type::Vector
                                     ? "a " + std::to_string(v.vector.size()) + "-vector"
                                     : std::string(reported(v))));
      return std::nullopt;
    }
    return ir::Vec3{v.vector[0], v.vector[1], v.vector[2]};
  }

  bool checkTimeAllowed(const Value& v, const ArgSpec& spec, const std::string& callee) {
    bool has_time = v.type == Value::Type::Number ? !v.number.isConst() : false;
    for (const Scalar& s : v.vector) has_time = has_time || !s.isConst();
    if (has_time && !spec.time_allowed) {
      diags_->error(v.range, "'" + std::string(spec.name) + "' of '" + callee +
                                "' must be a constant; it cannot depend on 'time'");
      return false;
    }
    return true;
  }

  // Applies a value rule; the message names the parameter and the value.
  bool checkRule(const Scalar& s, ValueRule rule, const SourceRange& range, const std::string& what) {
    const ir::Interval r = s.range();
    switch (rule) {
      case ValueRule::Any: return true;
      case ValueRule::Positive:
        if (s.isConst() && !(s.value > 0)) {
          diags_->error(range, what + " must be positive, got " + fmt(s.value));
          return false;
        }
        if (!s.isConst() && r.lo <= 0)
          diags_->warning(range, "time-range", what + " may reach " + fmt(r.lo) + " over time; it must stay positive");
        return true;
      case ValueRule::NonNegative:
        if (s.isConst() && !(s.value >= 0)) {
          diags_->error(range, what + " must not be negative, got " + fmt(s.value));
          return false;
        }
        return true;
    }
    return true;
  }

  std::optional<Scalar> numberArg(const Value& v, const ArgSpec& spec, const std::string& callee) {
    if (v.type != Value::Type::Number) {
      diags_->error(v.range, "'" + std::string(spec.name) + "' of '" + callee + "' must be a number, not " +
                                reported(v));
      return std::nullopt;
    }
    if (!checkTimeAllowed(v, spec, callee)) return std::nullopt;
    const std::string what = "'" + std::string(spec.name) + "' of '" + callee + "'";
    if (!checkShaderValue(v.number, v.range, what)) return std::nullopt;
    if (!checkRule(v.number, spec.rule, v.range, what)) return std::nullopt;
    return v.number;
  }

  std::optional<ir::Vec3> vectorArg(const Value& v, const ArgSpec& spec, const std::string& callee) {
    if (!checkTimeAllowed(v, spec, callee)) return std::nullopt;
    auto vec = asVec3(v, spec, callee);
    if (!vec) return std::nullopt;
    const std::string what = "'" + std::string(spec.name) + "' of '" + callee + "'";
    for (const Scalar* s : {&vec->x, &vec->y, &vec->z})
      if (!checkShaderValue(*s, v.range, "a component of " + what)) return std::nullopt;
    if (spec.rule == ValueRule::Positive)
      for (const Scalar* s : {&vec->x, &vec->y, &vec->z})
        if (!checkRule(*s, ValueRule::Positive, v.range, "every component of " + what)) return std::nullopt;
    if (spec.rule == ValueRule::NonNegative)
      for (const Scalar* s : {&vec->x, &vec->y, &vec->z})
        if (!checkRule(*s, ValueRule::NonNegative, v.range, "every component of " + what))
          return std::nullopt;
    const dvec3 direction = vec->isConst() ? vec->value() : dvec3(1);
    if (spec.nonzero && std::max({std::fabs(direction.x), std::fabs(direction.y), std::fabs(direction.z)}) == 0) {
      diags_->error(v.range, what + " must not be the zero vector");
      return std::nullopt;
    }
    if (spec.nonzero && vec->isConst()) {
      // Only the direction matters: rescale so the largest component is 1,
      // so normalising later neither overflows ([0.5, -1e308, 0.6]) nor
      // underflows ([1e-200, 0, 0]); components below float32's range vanish.
      dvec3 d = vec->value();
      d /= std::max({std::fabs(d.x), std::fabs(d.y), std::fabs(d.z)});
      for (int i = 0; i < 3; ++i)
        if (std::fabs(d[i]) < 1e-30) d[i] = 0;
      *vec = ir::constantVec(d);
    }
    return vec;
  }

  int materialOf(const BoundArgs& args) {
    if (!args.material) return -1;
    const Value& m = *args.material;
    if (m.type != Value::Type::Material) {
      diags_->error(m.range, std::string("'material' must be a material, not ") + reported(m));
      return -1;
    }
    material_used_[m.material] = true;
    return m.material;
  }

  // A shape, or a 2D profile when the node is one (ir::isProfile).
  static Value shapeValue(ir::NodeRef node, SourceRange range) {
    Value v;
    v.type = ir::isProfile(*node) ? Value::Type::Profile : Value::Type::Shape;
    v.shape = std::move(node);
    v.range = range;
    return v;
  }

  Value evalPrimitive(const ast::Expr& e, const PrimitiveInfo& info) {
    if (e.has_block) diags_->error(e.range, "'" + e.name + "' is a primitive and takes no block");
    if (info.kind == PrimitiveKind::Polygon) return evalPolygon(e, info);
    std::vector<ArgSpec> specs;
    for (const ParamSpec& p : info.params) specs.push_back(argSpecOf(p, info));
    BoundArgs args = bindArguments(e, specs, true);
    auto node = std::make_shared<ir::Node>();
    node->kind = ir::NodeKind::Primitive;
    node->primitive = info.kind;
    node->range = e.range;
    node->material = materialOf(args);
    bool ok = args.ok;
    for (size_t i = 0; i < specs.size(); ++i) {
      const ParamSpec& p = info.params[i];
      if (!args.values[i]) {
        if (!ok) continue;  // the other arguments are still checked: all errors in one run
        if (p.type == ParamType::Vector || p.type == ParamType::Vector2) {
          for (int c = 0; c < (p.type == ParamType::Vector ? 3 : 2); ++c)
            node->args.push_back(ir::constant(p.default_value[c]));
        } else {
          node->args.push_back(ir::constant(p.default_value.x));
        }
        continue;
      }
      if (p.type == ParamType::Vector) {
        auto v = vectorArg(*args.values[i], specs[i], e.name);
        if (!v) { ok = false; continue; }
        node->args.push_back(v->x);
        node->args.push_back(v->y);
        node->args.push_back(v->z);
      } else if (p.type == ParamType::Vector2) {
        auto v = vector2Arg(*args.values[i], specs[i], e.name);
        if (!v) { ok = false; continue; }
        node->args.push_back((*v)[0]);
        node->args.push_back((*v)[1]);
      } else {
        auto s = numberArg(*args.values[i], specs[i], e.name);
        if (!s) { ok = false; continue; }
        node->args.push_back(*s);
      }
    }
    if (!ok) return {};
    if (!checkPrimitiveValues(e, info, *node)) return {};
    return shapeValue(node, e.range);
  }

  // A 2-vector [x, y] (profiles' sizes); a number stands for [n, n].
  std::optional<std::array<Scalar, 2>> vector2Arg(const Value& v, const ArgSpec& spec, const std::string& callee) {
    if (!checkTimeAllowed(v, spec, callee)) return std::nullopt;
    std::array<Scalar, 2> out;
    if (v.type == Value::Type::Number) {
      out = {v.number, v.number};
    } else if (v.type == Value::Type::Vector && v.vector.size() == 2) {
      out = {v.vector[0], v.vector[1]};
    } else {
      diags_->error(v.range, "'" + std::string(spec.name) + "' of '" + callee + "' must be a 2-vector like [x, y], not " +
                                (v.type == Value::Type::Vector ? "a " + std::to_string(v.vector.size()) + "-vector"
                                                               : std::string(reported(v))));
      return std::nullopt;
    }
    const std::string what = "'" + std::string(spec.name) + "' of '" + callee + "'";
    for (const Scalar& s : out) {
      if (!checkShaderValue(s, v.range, "a component of " + what)) return std::nullopt;
      if (!checkRule(s, spec.rule, v.range, "every component of " + what)) return std::nullopt;
    }
    return out;
  }

  // polygon(points: [[x, y], ...]): the points are read from the syntax (a
  // list of vectors is no value of the language), constant, and must make a
  // simple polygon (then even-odd inside is the inside).
  Value evalPolygon(const ast::Expr& e, const PrimitiveInfo& info) {
    std::optional<Value> material;
    const ast::Expr* points = nullptr;
    bool ok = !e.has_block;
    for (const ast::Argument& a : e.arguments) {
      if ((a.name.empty() || a.name == "points") && !points) {
        points = a.value.get();
      } else if (a.name == "material" && !material) {
        material = evalExpr(*a.value);
      } else {
        const std::string near = nearestName(a.name, {"points", "material"});
        diags_->error(a.name.empty() ? a.value->range : a.name_range,
                      a.name.empty() ? std::string("'polygon' takes 1 positional argument")
                                     : "'polygon' has no parameter '" + a.name + "' (or it is given twice)" +
                                           (near.empty() || near == a.name ? "" : "; did you mean '" + near + "'?"));
        ok = false;
      }
    }
    if (!points) {
      if (ok) diags_->error(e.range, "'polygon' needs 'points'");
      return {};
    }
    if (points->reported) return {};
    if (points->kind != ast::ExprKind::Vector) {
      diags_->error(points->range, "'points' of 'polygon' must be a list of points [[x, y], ...]");
      return {};
    }
    auto node = std::make_shared<ir::Node>();
    node->kind = ir::NodeKind::Primitive;
    node->primitive = info.kind;
    node->range = e.range;
    for (const ast::ExprPtr& item : points->operands) {
      Value v = evalExpr(*item);
      if (v.type == Value::Type::Error) { ok = false; continue; }
      bool constant = v.type == Value::Type::Vector && v.vector.size() == 2;
      for (const Scalar& c : v.vector) constant = constant && c.isConst() && std::isfinite(c.value);
      if (!constant) {
        diags_->error(v.range, "each point of a polygon must be a constant [x, y], not " +
                                  (v.type == Value::Type::Vector ? "a " + std::to_string(v.vector.size()) + "-vector"
                                                                 : std::string(reported(v))));
        ok = false;
        continue;
      }
      node->points.emplace_back(v.vector[0].value, v.vector[1].value);
    }
    if (!ok) return {};
    if (node->points.size() > kMaxPolygonPoints) {
      diags_->error(points->range, "a polygon takes at most " + std::to_string(kMaxPolygonPoints) + " points, got " +
                                       std::to_string(node->points.size()));
      return {};
    }
    if (const std::string problem = polygonProblem(node->points); !problem.empty()) {
      diags_->error(points->range, problem);
      return {};
    }
    if (material && material->type != Value::Type::Error) {
      BoundArgs args;
      args.material = material;
      node->material = materialOf(args);
    }
    return shapeValue(node, e.range);
  }

  // Cross-parameter checks a single rule cannot express.
  bool checkPrimitiveValues(const ast::Expr& e, const PrimitiveInfo& info, ir::Node& node) {
    auto c = [&](size_t i) { return node.args[i].isConst() ? node.args[i].value : NAN; };
    switch (info.kind) {
      case PrimitiveKind::Menger: {
        const double level = c(0);
        if (level != std::floor(level) || level > kMaxMengerLevel) {
          diags_->error(e.range, "menger 'level' must be a whole number from 0 to " +
                                    std::to_string(kMaxMengerLevel) + " (deeper holes are below "
                                    "float32 marching precision), got " + fmt(level));
          return false;
        }
        return true;
      }
      case PrimitiveKind::Box: {
        const double rounding = c(3);
        const double smallest = std::min({c(0), c(1), c(2)});
        if (rounding > smallest / 2) {
          diags_->error(e.range, "box 'rounding' (" + fmt(rounding) +
                                    ") must be at most half the smallest side (" +
                                    fmt(smallest / 2) + ")");
          return false;
        }
        return true;
      }
      case PrimitiveKind::Rect: {
        const double rounding = c(2), smallest = std::min(c(0), c(1));
        if (rounding > smallest / 2) {
          diags_->error(e.range, "rect 'rounding' (" + fmt(rounding) + ") must be at most half the smaller side (" +
                                    fmt(smallest / 2) + ")");
          return false;
        }
        return true;
      }
      case PrimitiveKind::RoundCone:
        // Otherwise one sphere holds the other and no cone touches both.
        if (c(2) <= std::fabs(c(0) - c(1))) {
          diags_->error(e.range, "round_cone 'height' (" + fmt(c(2)) +
                                    ") must exceed the difference of 'bottom' and 'top' (" +
                                    fmt(std::fabs(c(0) - c(1))) + "), or one sphere holds the other");
          return false;
        }
        return true;
      case PrimitiveKind::Torus:
        if (c(1) > c(0))
          diags_->warning(e.range, "bound", "torus 'minor' > 'major' makes a spindle torus; its distance "
                                  "is only a bound near the axis");
        return true;
      default: return true;
    }
  }

  Value evalOperator(const ast::Expr& e, const BuiltinSignature& sig) {
    BoundArgs args = bindArguments(e, sig.args, true);
    std::vector<ir::NodeRef> children;
    bool ok = args.ok;
    if (!e.has_block) {
      diags_->error(e.range, "'" + e.name + "' needs a block of shapes: '" + e.name + "(...) { ... }'");
      ok = false;
    }
    // extrude and revolve take profiles; the CSG operators and planar moves
    // take either, but not both at once; the others take shapes only.
    const bool takes_profiles = e.name == "extrude" || e.name == "revolve";
    const bool planar = e.name == "union" || e.name == "intersect" || e.name == "subtract" ||
                        e.name == "translate" || e.name == "rotate" || e.name == "scale" ||
                        e.name == "round" || e.name == "shell";
    std::optional<Value::Type> first_kind;
    for (const ast::ExprPtr& c : e.children) {
      Value v = evalExpr(*c);
      if (v.type == Value::Type::Error) { ok = false; continue; }
      if (v.type != Value::Type::Shape && v.type != Value::Type::Profile) {
        diags_->error(v.range, std::string("'") + e.name + "' expects " + (takes_profiles ? "2D profiles" : "shapes") +
                                  " in its block, not " + reported(v));
        ok = false;
        continue;
      }
      if (takes_profiles && v.type != Value::Type::Profile) {
        diags_->error(v.range, "'" + e.name + "' takes 2D profiles in its block (circle, rect, polygon, hexagon), "
                               "not a shape");
        ok = false;
        continue;
      }
      if (!takes_profiles && v.type == Value::Type::Profile && !planar) {
        diags_->error(v.range, "'" + e.name + "' does not take a 2D profile; extrude or revolve it first");
        ok = false;
        continue;
      }
      if (first_kind && *first_kind != v.type) {
        diags_->error(v.range, "'" + e.name + "' cannot mix 2D profiles and shapes in one block; extrude or "
                               "revolve the profile first");
        ok = false;
        continue;
      }
      first_kind = v.type;
      children.push_back(v.shape);
    }
    if (e.has_block && children.empty() && ok) {
      diags_->error(e.range, "'" + e.name + "' has an empty block");
      return {};
    }
    const bool of_profiles = first_kind == Value::Type::Profile && !takes_profiles;
    // morph's 't' is checked even when a child has an error: all errors in one run.
    std::optional<Scalar> morph_t;
    if (e.name == "morph" && args.ok && args.values[0]) {
      morph_t = numberArg(*args.values[0], sig.args[0], e.name);
      if (!morph_t || !checkMorphAmount(*morph_t, args.values[0]->range)) return {};
    }
    if (!ok) return {};
    auto node = std::make_shared<ir::Node>();
    node->range = e.range;
    node->material = materialOf(args);
    auto arg = [&](size_t i) -> const Value* { return args.values[i] ? &*args.values[i] : nullptr; };
    const std::string& name = e.name;
    // Several children under a domain operation mean their union.
    auto single = [&]() -> ir::NodeRef {
      if (children.size() == 1) return children[0];
      auto u = std::make_shared<ir::Node>();
      u->kind = ir::NodeKind::Union;
      u->range = e.range;
      u->children = children;
      return u;
    };
    if (name == "union" || name == "intersect" || name == "subtract") {
      node->kind = name == "union" ? ir::NodeKind::Union
                 : name == "intersect" ? ir::NodeKind::Intersect : ir::NodeKind::Subtract;
      node->smooth = ir::constant(0);
      if (const Value* v = arg(0)) {
        auto s = numberArg(*v, sig.args[0], name);
        if (!s) return {};
        node->smooth = *s;
        if (!s->isConst() || s->value > 0)
          diags_->warning(e.name_range, "bound", "smooth '" + name + "' gives a distance bound, not an "
                                       "exact distance (marching takes smaller steps near it)");
      }
      if (name == "subtract" && children.size() < 2)
        diags_->warning(e.range, "subtract-nothing", "'subtract' with one shape subtracts nothing");
      node->children = children;
      return shapeValue(node, e.range);
    }
    if (name == "morph") {
      if (children.size() != 2) {
        diags_->error(e.range, "'morph' blends exactly 2 shapes, got " + std::to_string(children.size()));
        return {};
      }
      if (!morph_t) return {};
      node->kind = ir::NodeKind::Morph;
      node->amount = *morph_t;
      node->children = children;
      diags_->warning(e.name_range, "bound", "'morph' gives a distance bound, not an exact distance");
      return shapeValue(node, e.range);
    }
    node->children = {single()};
    if (name == "translate") {
      // A profile moves in its plane: [x, y] (or [x, y, 0]).
      Value offset = *arg(0);
      if (of_profiles && offset.type == Value::Type::Vector && offset.vector.size() == 2)
        offset.vector.push_back(ir::constant(0));
      auto v = vectorArg(offset, sig.args[0], name);
      if (!v) return {};
      if (of_profiles && !(v->z.isConst() && v->z.value == 0)) {
        diags_->error(arg(0)->range, "a 2D profile moves in its plane: 'offset' must be [x, y]");
        return {};
      }
      node->kind = ir::NodeKind::Translate;
      node->vec = *v;
    } else if (name == "rotate") {
      Value r = evalRotate(e, sig, args, node);
      if (of_profiles && r.type != Value::Type::Error && !rotatesInPlane(*r.shape, children)) {
        diags_->error(e.range, "a 2D profile turns in its plane: rotate it about the z axis "
                               "(axis: [0, 0, 1]), or rotate the extruded shape");
        return {};
      }
      return r;
    } else if (name == "scale") {
      const Value& f = *arg(0);
      if (of_profiles && f.type != Value::Type::Number) {
        diags_->error(f.range, "a 2D profile scales by a number only");
        return {};
      }
      if (f.type == Value::Type::Number) {
        auto s = numberArg(f, {"factor", ArgType::Number, ValueRule::Positive, true, true}, name);
        if (!s) return {};
        node->kind = ir::NodeKind::Scale;
        node->amount = *s;
      } else {
        auto v = vectorArg(f, {"factor", ArgType::Vector3, ValueRule::Positive, true, false}, name);
        if (!v) return {};
        node->kind = ir::NodeKind::ScaleNonUniform;
        node->vec = *v;
        diags_->warning(e.name_range, "bound", "non-uniform 'scale' gives a distance bound, not an exact "
                                     "distance (marching takes smaller steps)");
      }
    } else if (name == "reflect") {
      auto n = vectorArg(*arg(0), sig.args[0], name);
      if (!n) return {};
      const dvec3 unit = glm::normalize(n->value());
      node->kind = ir::NodeKind::Reflect;
      node->vec = ir::constantVec(unit);
      node->amount = ir::constant(0);
      if (const Value* o = arg(1)) {
        auto s = numberArg(*o, sig.args[1], name);
        if (!s) return {};
        node->amount = *s;
      }
    } else if (name == "repeat") {
      auto cell = vectorArg(*arg(0), sig.args[0], name);
      if (!cell) return {};
      node->kind = ir::NodeKind::Repeat;
      node->vec = *cell;
      if (glm::length(cell->value()) == 0) {
        diags_->error(arg(0)->range, "'cell' of 'repeat' must be positive along at least one axis");
        return {};
      }
      if (const Value* c = arg(1)) {
        auto counts = vectorArg(*c, sig.args[1], name);
        if (!counts) return {};
        const dvec3 cv = counts->value();
        for (int i = 0; i < 3; ++i) {
          if (cv[i] != std::floor(cv[i]) || cv[i] > kMaxRepeatCount) {
            diags_->error(c->range, "'count' of 'repeat' must hold whole numbers from 0 (infinite) to " +
                                       std::to_string(kMaxRepeatCount) + ", got " + fmt(cv[i]));
            return {};
          }
          node->count[i] = static_cast<int>(cv[i]);
        }
      }
    } else if (name == "extrude") {
      auto s = numberArg(*arg(0), sig.args[0], name);
      if (!s) return {};
      node->kind = ir::NodeKind::Extrude;
      node->amount = ir::binary('*', *s, ir::constant(0.5));  // the IR keeps the half depth
    } else if (name == "revolve") {
      node->kind = ir::NodeKind::Revolve;
      node->amount = ir::constant(0);
      if (const Value* o = arg(0)) {
        auto s = numberArg(*o, sig.args[0], name);
        if (!s) return {};
        node->amount = *s;
      }
    } else if (name == "twist" || name == "bend") {
      auto s = numberArg(*arg(0), sig.args[0], name);
      if (!s) return {};
      if (!s->range().bounded()) {
        diags_->error(arg(0)->range, name + " 'rate' is unbounded over time, so no step size is safe; keep it in a "
                                     "range, e.g. with clamp() or sin()");
        return {};
      }
      node->kind = name == "twist" ? ir::NodeKind::Twist : ir::NodeKind::Bend;
      node->amount = *s;
      diags_->warning(e.name_range, "bound", "'" + name + "' gives a distance bound, not an exact distance (marching "
                                             "divides it by the " + name + "'s stretch)");
    } else if (name == "displace") {
      auto a = numberArg(*arg(0), sig.args[0], name);
      if (!a) return {};
      std::optional<Scalar> scale = ir::constant(1);
      if (const Value* v = arg(1)) scale = numberArg(*v, sig.args[1], name);
      if (!scale) return {};
      for (const auto& [s, what, i] : {std::tuple{*a, "amplitude", 0}, std::tuple{*scale, "scale", 1}}) {
        if (!s.range().bounded()) {
          diags_->error(arg(i)->range, std::string("displace '") + what + "' is unbounded over time, so no step "
                                       "size is safe; keep it in a range, e.g. with clamp() or sin()");
          return {};
        }
      }
      node->count.x = 1;
      if (const Value* v = arg(2)) {
        auto o = numberArg(*v, sig.args[2], name);
        if (!o) return {};
        if (o->value != std::floor(o->value) || o->value > kMaxDisplaceOctaves) {
          diags_->error(v->range, "'octaves' of 'displace' must be a whole number from 1 to " +
                                      std::to_string(kMaxDisplaceOctaves) + ", got " + fmt(o->value));
          return {};
        }
        node->count.x = static_cast<int>(o->value);
      }
      node->kind = ir::NodeKind::Displace;
      node->amount = *a;
      node->vec = {*scale, ir::constant(0), ir::constant(0)};
      diags_->warning(e.name_range, "bound", "'displace' gives a distance bound, not an exact distance (marching "
                                             "divides it by the noise's stretch)");
    } else if (name == "repeat_polar") {
      auto c = numberArg(*arg(0), sig.args[0], name);
      if (!c) return {};
      if (c->value != std::floor(c->value) || c->value > kMaxRepeatCount) {
        diags_->error(arg(0)->range, "'count' of 'repeat_polar' must be a whole number from 1 to " +
                                         std::to_string(kMaxRepeatCount) + ", got " + fmt(c->value));
        return {};
      }
      node->kind = ir::NodeKind::RepeatPolar;
      node->count.x = static_cast<int>(c->value);
    } else if (name == "round" || name == "shell") {
      auto s = numberArg(*arg(0), sig.args[0], name);
      if (!s) return {};
      node->kind = name == "round" ? ir::NodeKind::Round : ir::NodeKind::Shell;
      // The IR keeps the offset from the surface: a shell's half thickness.
      node->amount = name == "round" ? *s : ir::binary('*', *s, ir::constant(0.5));
    } else if (name == "elongate") {
      auto v = vectorArg(*arg(0), sig.args[0], name);
      if (!v) return {};
      node->kind = ir::NodeKind::Elongate;
      // The parameter is the full added length; the IR keeps half extents.
      node->vec = {ir::binary('*', v->x, ir::constant(0.5)), ir::binary('*', v->y, ir::constant(0.5)),
                   ir::binary('*', v->z, ir::constant(0.5))};
    }
    return shapeValue(node, e.range);
  }

  // ---- mesh(file: "part.stl", material: m) (meshin/, docs/mesh_in.md) ----

  Value evalMesh(const ast::Expr& e) {
    if (e.has_block) diags_->error(e.range, "'mesh' is a primitive and takes no block");
    const ast::Expr* file = nullptr;
    std::optional<Value> material;
    bool ok = true;
    size_t positional = 0;
    for (const ast::Argument& a : e.arguments) {
      std::string name = a.name;
      if (name.empty()) name = positional++ == 0 ? "file" : "";
      if (name == "file" && !file) file = a.value.get();
      else if (name == "material" && !material) material = evalExpr(*a.value);
      else {
        const std::string near = nearestName(name, {"file", "material"});
        diags_->error(a.name.empty() ? a.value->range : a.name_range,
                      name.empty() ? "'mesh' takes at most 1 positional argument (the file)"
                                   : "'mesh' has no parameter '" + name + "' (or it is given twice)" +
                                         (near.empty() || near == name ? "" : "; did you mean '" + near + "'?"));
        ok = false;
      }
    }
    if (!file) {
      if (ok) diags_->error(e.range, "'mesh' needs 'file': mesh(file: \"part.stl\")");
      return {};
    }
    if (file->kind != ast::ExprKind::String) {
      if (!file->reported)
        diags_->error(file->range, "'file' of 'mesh' must be a string, the path of an STL, OBJ, glTF or GLB "
                                   "file: mesh(file: \"part.stl\")");
      return {};
    }
    int material_id = -1;
    if (material) {
      BoundArgs bound;
      bound.material = material;
      material_id = materialOf(bound);
      if (material->type != Value::Type::Material) ok = false;
    }
    if (!ok) return {};
    const std::string path = resolveBesides(file->range.file ? file->range.file->path : source_.path, file->name);
    scene_.data_files.push_back(path);
    std::shared_ptr<MeshShape> shape = loadMesh(path, file->name, file->range, options_.mesh_mode, *diags_);
    if (!shape) return {};
    auto node = std::make_shared<ir::Node>();
    node->kind = ir::NodeKind::Mesh;
    node->range = e.range;
    node->material = material_id;
    node->mesh = std::move(shape);
    return shapeValue(node, e.range);
  }

  // ---- instances(positions: [[x, y, z], ...] | file("points.csv")) { shape } ----

  // The positions are read from the syntax (a list of vectors is no value of
  // the language): each row a constant [x, y, z] or [x, y, z, scale].
  bool positionsFrom(const ast::Expr& arg, std::vector<PositionRow>& rows) {
    if (arg.kind == ast::ExprKind::Call && arg.name == "file") {
      if (arg.arguments.size() != 1 || !arg.arguments[0].name.empty() ||
          arg.arguments[0].value->kind != ast::ExprKind::String || arg.has_block) {
        diags_->error(arg.range, "'file' takes one string, the path of a CSV file: file(\"points.csv\")");
        return false;
      }
      const ast::Expr& name = *arg.arguments[0].value;
      const std::string path = resolveBesides(name.range.file ? name.range.file->path : source_.path, name.name);
      scene_.data_files.push_back(path);
      PointFile file = readPointFile(path);
      if (!file.readable) {
        // Why, and where it looked: the path is relative to the scene's folder.
        const std::string reason = !file.unreadable_reason.empty() ? file.unreadable_reason
                                   : ::access(path.c_str(), R_OK) != 0 ? std::strerror(errno)
                                   : std::filesystem::is_directory(path) ? "it is a directory"
                                                                         : "it cannot be opened";
        std::error_code ignored;
        const std::string tried = std::filesystem::absolute(path, ignored).lexically_normal().string();
        diags_->error(name.range, "cannot read '" + name.name + "': " + reason + " (looked for '" +
                                     tried + "')");
        return false;
      }
      if (file.bad_rows > 0) {
        // Each bad field at its place in the CSV (file:line:col, its line and a
        // caret), with a note at the file(...) that read it.
        const SourceFile& csv = diags_->keep(std::make_unique<SourceFile>(path, std::move(file.text)));
        for (const PointFileError& bad : file.errors) {
          Diagnostic& d = diags_->error({&csv, bad.begin, bad.end}, bad.message);
          d.notes.push_back({Severity::Note, name.range, "in the positions read from '" + name.name + "' here", {}});
        }
        if (file.bad_rows > file.errors.size())
          diags_->error(name.range, "'" + name.name + "' has " + std::to_string(file.bad_rows) +
                                       " bad rows; the first " + std::to_string(file.errors.size()) +
                                       " are shown");
        return false;
      }
      if (file.rows.empty()) {
        diags_->error(name.range, "'" + name.name + "' holds no positions");
        return false;
      }
      rows = std::move(file.rows);
      return true;
    }
    if (arg.reported) return false;  // the parser reported it
    if (arg.kind != ast::ExprKind::Vector) {
      diags_->error(arg.range, "'positions' of 'instances' must be a list [[x, y, z], ...] or "
                              "file(\"points.csv\")");
      return false;
    }
    bool ok = true;
    for (const ast::ExprPtr& item : arg.operands) {
      Value v = evalExpr(*item);
      if (v.type == Value::Type::Error) { ok = false; continue; }
      bool constant = v.type == Value::Type::Vector;
      for (const Scalar& s : v.vector) constant = constant && s.isConst();
      if (v.type != Value::Type::Vector || (v.vector.size() != 3 && v.vector.size() != 4) || !constant) {
        diags_->error(v.range, "each position must be a constant [x, y, z] or [x, y, z, scale]");
        ok = false;
        continue;
      }
      PositionRow row;
      row.position = {v.vector[0].value, v.vector[1].value, v.vector[2].value};
      if (v.vector.size() == 4) row.scale = v.vector[3].value;
      if (!(row.scale > 0)) {
        diags_->error(v.range, "the scale of a position must be positive, got " + fmt(row.scale));
        ok = false;
        continue;
      }
      rows.push_back(row);
    }
    return ok;
  }

  Value evalInstances(const ast::Expr& e, const BuiltinSignature& sig) {
    const ast::Expr* positions = nullptr;
    const ast::Expr* smooth = nullptr;
    std::optional<Value> material;
    bool ok = true;
    size_t positional = 0;
    for (const ast::Argument& a : e.arguments) {
      std::string name = a.name;
      if (name.empty()) name = positional < sig.args.size() ? sig.args[positional++].name : "";
      if (name == "positions" && !positions) positions = a.value.get();
      else if (name == "smooth" && !smooth) smooth = a.value.get();
      else if (name == "material" && !material) material = evalExpr(*a.value);
      else {
        const std::string near = nearestName(name, {"positions", "smooth", "material"});
        diags_->error(a.name.empty() ? a.value->range : a.name_range,
                     name.empty() ? "'instances' takes at most 2 positional arguments"
                                  : "'instances' has no parameter '" + name + "' (or it is given twice)" +
                                        (near.empty() || near == name ? "" : "; did you mean '" + near + "'?"));
        ok = false;
      }
    }
    if (!positions && ok) {
      diags_->error(e.range, "'instances' needs 'positions'");
      ok = false;
    }
    std::vector<PositionRow> rows;
    if (positions && !positionsFrom(*positions, rows)) ok = false;
    std::vector<ir::NodeRef> children;
    if (!e.has_block) {
      diags_->error(e.range, "'instances' needs a block with the shape to place: 'instances(...) { ... }'");
      ok = false;
    }
    for (const ast::ExprPtr& c : e.children) {
      Value v = evalExpr(*c);
      if (v.type == Value::Type::Error) { ok = false; continue; }
      if (v.type != Value::Type::Shape) {
        diags_->error(v.range, std::string("'instances' expects shapes in its block, not ") + reported(v));
        ok = false;
        continue;
      }
      children.push_back(v.shape);
    }
    if (e.has_block && children.empty() && ok) {
      diags_->error(e.range, "'instances' has an empty block");
      return {};
    }
    Scalar k = ir::constant(0);
    if (smooth) {
      Value v = evalExpr(*smooth);
      auto s = v.type == Value::Type::Error ? std::nullopt : numberArg(v, sig.args[1], "instances");
      if (!s) ok = false;
      else k = *s;
    }
    if (rows.size() > kMaxInstances) {
      diags_->error(positions->range, "at most " + std::to_string(kMaxInstances) + " instances, got " +
                                         std::to_string(rows.size()));
      ok = false;
    }
    if (!ok) return {};
    ir::NodeRef shape = children[0];
    if (children.size() > 1) {
      shape = std::make_shared<ir::Node>();
      shape->kind = ir::NodeKind::Union;
      shape->range = e.range;
      shape->children = children;
    }
    auto set = std::make_shared<ir::InstanceSet>();
    set->origin = "instances(...) of " + std::to_string(rows.size());
    set->instances.reserve(rows.size());
    for (const PositionRow& r : rows) {
      // local = (p - position) / scale, distance * scale.
      ir::Instance inst;
      inst.offset = -r.position / r.scale;
      if (r.scale != 1) {
        inst.transform = static_cast<int>(set->transforms.size());
        set->transforms.push_back({glm::dmat3(1.0 / r.scale), r.scale});
      }
      set->instances.push_back(inst);
    }
    auto node = std::make_shared<ir::Node>();
    node->kind = ir::NodeKind::Instances;
    node->range = e.range;
    node->smooth = k;
    node->children = {shape};
    node->instances = set;
    if (material && material->type != Value::Type::Error) {
      BoundArgs args;
      args.material = material;
      node->material = materialOf(args);
    }
    return shapeValue(node, e.range);
  }

  // Outside [0, 1] morph extrapolates, and its distance must be divided by
  // |t| + |1 - t| (passes/analyze.cpp) to stay a bound: an unbounded t allows
  // no step at all, a huge one a step too small to reach anything.
  bool checkMorphAmount(const Scalar& t, const SourceRange& range) {
    const ir::Interval r = t.range();
    if (!r.bounded()) {
      diags_->error(range, "morph 't' is unbounded over time, so no step size is safe; keep it in a "
                          "range, e.g. with clamp() or sin()");
      return false;
    }
    const double stretch = std::max(std::fabs(r.lo) + std::fabs(1 - r.lo), std::fabs(r.hi) + std::fabs(1 - r.hi));
    if (stretch > kMaxMorphStretch) {
      diags_->error(range, "morph 't' ranges over " + rangeText(r) + "; marching must divide its distance by " +
                              fmt(stretch) + ", at most " + fmt(kMaxMorphStretch) + " (t within [" +
                              fmt((1 - kMaxMorphStretch) / 2) + ", " + fmt((1 + kMaxMorphStretch) / 2) + "])");
      return false;
    }
    return true;
  }

  // Whether the rotations evalRotate made (down to the block's children) all
  // turn about the z axis, keeping a profile in its plane.
  static bool rotatesInPlane(const ir::Node& n, const std::vector<ir::NodeRef>& children) {
    for (const ir::Node* r = &n; r && std::find_if(children.begin(), children.end(), [&](const ir::NodeRef& c) {
                                         return c.get() == r;
                                       }) == children.end();
         r = r->children.empty() ? nullptr : r->children[0].get()) {
      if (r->kind != ir::NodeKind::Rotate) continue;
      const dvec3 axis = r->vec.value();
      if (axis.x != 0 || axis.y != 0) return false;
    }
    return true;
  }

  Value evalRotate(const ast::Expr& e, const BuiltinSignature& sig, const BoundArgs& args,
                   ir::NodeRef node) {
    // rotate(axis, degrees) or rotate(euler: [x, y, z]) (degrees, applied x, then y, then z).
    const auto& axis = args.values[0];
    const auto& degrees = args.values[1];
    const auto& euler = args.values[2];
    if (euler && (axis || degrees)) {
      diags_->error(e.range, "'rotate' takes either 'axis' and 'degrees' or 'euler', not both");
      return {};
    }
    if (euler) {
      auto angles = vectorArg(*euler, sig.args[2], "rotate");
      if (!angles) return {};
      // Applying x first means x is innermost: R = Rz * Ry * Rx.
      ir::NodeRef inner = node->children[0];
      const Scalar* comps[3] = {&angles->x, &angles->y, &angles->z};
      for (int i = 0; i < 3; ++i) {
        if (comps[i]->isConst() && comps[i]->value == 0) continue;
        auto r = std::make_shared<ir::Node>();
        r->kind = ir::NodeKind::Rotate;
        r->range = e.range;
        dvec3 ax(0);
        ax[i] = 1;
        r->vec = ir::constantVec(ax);
        r->amount = *comps[i];
        r->children = {inner};
        inner = r;
      }
      if (inner == node->children[0]) {  // all zero: still a node, for the material
        node->kind = ir::NodeKind::Translate;
        node->vec = ir::constantVec(dvec3(0));
        return shapeValue(node, e.range);
      }
      inner->material = node->material;
      return shapeValue(inner, e.range);
    }
    if (!axis || !degrees) {
      diags_->error(e.range, "'rotate' needs 'axis' and 'degrees', or 'euler'");
      return {};
    }
    auto ax = vectorArg(*axis, sig.args[0], "rotate");
    auto deg = numberArg(*degrees, sig.args[1], "rotate");
    if (!ax || !deg) return {};
    node->kind = ir::NodeKind::Rotate;
    node->vec = ir::constantVec(glm::normalize(ax->value()));
    node->amount = *deg;
    return shapeValue(node, e.range);
  }

  Value evalMaterial(const ast::Expr& e, const BuiltinSignature& sig) {
    if (e.has_block) diags_->error(e.range, "'" + e.name + "' is a material and takes no block");
    // a failed one: the others are still checked
    BoundArgs args = bindArguments(e, sig.args, false, e.name == "sky" ? "map" : nullptr);
    ir::Material m;
    m.range = e.range;
    auto vec = [&](size_t i, dvec3 fallback) -> std::optional<dvec3> {
      if (!args.values[i]) return fallback;
      if (args.values[i]->type == Value::Type::Field && sig.args[i].type == ArgType::Colour) {
        // The constant colour stands for the field where one colour is
        // needed (the IR dump, mesh materials): the mean of its two colours.
        m.field = args.values[i]->field;
        if (m.field->kind == ir::FieldKind::Texture) {  // the image's mean
          const std::vector<float>& rgb = m.field->image->rgb;
          dvec3 sum(0);
          for (size_t t = 0; t + 2 < rgb.size(); t += 3) sum += dvec3(rgb[t], rgb[t + 1], rgb[t + 2]);
          return sum / std::max(1.0, double(rgb.size() / 3));
        }
        const dvec3 a = m.field->a.value(), b = m.field->b.value();
        if (e.name != "emissive" && std::max({a.x, a.y, a.z, b.x, b.y, b.z}) > 1)
          diags_->warning(args.values[i]->range, "energy", "'" + std::string(sig.args[i].name) +
                                                              "' above 1 reflects more light than arrives "
                                                              "(energy is not conserved)");
        return (a + b) * 0.5;
      }
      auto v = vectorArg(*args.values[i], sig.args[i], e.name);
      if (!v) return std::nullopt;
      return v->value();
    };
    auto num = [&](size_t i, double fallback) -> std::optional<double> {
      if (!args.values[i]) return fallback;
      auto s = numberArg(*args.values[i], sig.args[i], e.name);
      if (!s) return std::nullopt;
      return s->value;
    };
    auto checkUnit = [&](size_t i, const dvec3& c) {
      if (args.values[i] && (c.x > 1 || c.y > 1 || c.z > 1))
        diags_->warning(args.values[i]->range, "energy", "'" + std::string(sig.args[i].name) +
                                                  "' above 1 reflects more light than arrives "
                                                  "(energy is not conserved)");
    };
    if (e.name == "diffuse" || e.name == "mirror" || e.name == "metal") {
      auto a = vec(0, dvec3(0.8));
      if (!a) return {};
      if (!m.field) checkUnit(0, *a);
      m.model = e.name == "diffuse" ? ir::MaterialModel::Diffuse
              : e.name == "mirror" ? ir::MaterialModel::Mirror : ir::MaterialModel::Metal;
      m.albedo = ir::constantVec(*a);
      if (e.name == "metal") {
        auto r = num(1, 0.3);
        if (!r) return {};
        if (*r > 1) {
          diags_->error(args.values[1]->range, "'roughness' of 'metal' must be in [0, 1], got " + fmt(*r));
          return {};
        }
        m.roughness = *r;
      }
    } else if (e.name == "glass") {
      auto ior = num(0, 1.5);
      auto tint = vec(1, dvec3(1));
      if (!ior || !tint) return {};
      if (*ior < 1 || *ior > 4) {
        diags_->error(args.values[0]->range, "'ior' of 'glass' must be in [1, 4], got " + fmt(*ior));
        return {};
      }
      if (!m.field) checkUnit(1, *tint);
      m.model = ir::MaterialModel::Glass;
      m.ior = *ior;
      m.albedo = ir::constantVec(*tint);
    } else if (e.name == "emissive") {
      auto color = vec(0, dvec3(1));
      auto strength = num(1, 1);
      if (!color || !strength) return {};
      m.model = ir::MaterialModel::Emissive;
      m.emission = ir::constantVec(*color * *strength);
      m.albedo = ir::constantVec(dvec3(0));
      m.field_scale = *strength;
    }
    if (!args.ok) return {};
    if (m.emission.x.expr == nullptr && m.model != ir::MaterialModel::Emissive)
      m.emission = ir::constantVec(dvec3(0));
    Value v;
    v.type = Value::Type::Material;
    v.material = static_cast<int>(scene_.materials.size());
    v.range = e.range;
    scene_.materials.push_back(m);
    material_used_.push_back(false);
    return v;
  }

  // texture(file: "wood.png", projection: triplanar, size: 1): its file is a
  // string and its projection a name, neither a value of the language, so
  // they are read from the syntax (as instances' positions are).
  Value evalTexture(const ast::Expr& e, const BuiltinSignature& sig) {
    bool ok = true;
    if (e.has_block) {
      diags_->error(e.range, "'texture' is a colour field and takes no block");
      ok = false;
    }
    const ast::Argument* given[3] = {nullptr, nullptr, nullptr};
    size_t positional = 0;
    bool seen_named = false;
    for (const ast::Argument& a : e.arguments) {
      size_t index = sig.args.size();
      if (a.name.empty()) {
        if (seen_named) {
          diags_->error(a.value->range, "positional argument after a named one");
          ok = false;
          continue;
        }
        index = positional++;
        if (index >= sig.args.size()) {
          diags_->error(a.value->range, "'texture' takes at most 3 positional arguments");
          ok = false;
          continue;
        }
      } else {
        seen_named = true;
        for (size_t i = 0; i < sig.args.size(); ++i)
          if (a.name == sig.args[i].name) index = i;
        if (index == sig.args.size()) {
          std::string message = "'texture' has no parameter '" + a.name + "'";
          const std::string near = nearestName(a.name, {"file", "projection", "size"});
          if (!near.empty()) message += "; did you mean '" + near + "'?";
          diags_->error(a.name_range, message);
          ok = false;
          continue;
        }
      }
      if (given[index]) {
        diags_->error(a.name.empty() ? a.value->range : a.name_range, "'" + std::string(sig.args[index].name) + "' is given twice");
        ok = false;
        continue;
      }
      given[index] = &a;
    }
    auto f = std::make_shared<ir::ColorField>();
    f->kind = ir::FieldKind::Texture;
    f->range = e.range;
    f->size = ir::constant(1);
    if (given[1]) {
      const ast::Expr& p = *given[1]->value;
      if (p.kind != ast::ExprKind::Name || p.name != "triplanar") {
        diags_->error(p.range, "'projection' of 'texture' must be 'triplanar' (the only projection so far)");
        ok = false;
      }
    }
    if (given[2]) {
      auto size = numberArg(evalExpr(*given[2]->value), sig.args[2], "texture");
      if (!size) ok = false;
      else f->size = *size;
    }
    if (!given[0]) {
      if (ok) diags_->error(e.range, "'texture' needs 'file', as in texture(file: \"wood.png\")");
      return {};
    }
    const ast::Expr& name = *given[0]->value;
    if (name.kind != ast::ExprKind::String) {
      diags_->error(name.range, "'file' of 'texture' must be a string naming a PNG or EXR image, as in "
                                "texture(file: \"wood.png\")");
      return {};
    }
    if (!ok) return {};
    const std::string path = resolveBesides(name.range.file ? name.range.file->path : source_.path, name.name);
    scene_.data_files.push_back(path);
    ImageFile image = readImageFile(path);
    if (!image.image) {
      std::error_code ignored;
      const std::string tried = std::filesystem::absolute(path, ignored).lexically_normal().string();
      diags_->error(name.range, "cannot read '" + name.name + "': " + image.reason + " (looked for '" + tried + "')");
      return {};
    }
    f->image = std::move(image.image);
    Value v;
    v.type = Value::Type::Field;
    v.field = f;
    v.range = e.range;
    return v;
  }

  // A colour field: checker, stripes, gradient, noise or texture (ir::ColorField).
  Value evalField(const ast::Expr& e, const BuiltinSignature& sig) {
    if (e.name == "texture") return evalTexture(e, sig);
    if (e.has_block) diags_->error(e.range, "'" + e.name + "' is a colour field and takes no block");
    BoundArgs args = bindArguments(e, sig.args, false);
    if (!args.ok) return {};
    auto f = std::make_shared<ir::ColorField>();
    f->range = e.range;
    f->kind = e.name == "checker" ? ir::FieldKind::Checker
            : e.name == "stripes" ? ir::FieldKind::Stripes
            : e.name == "gradient" ? ir::FieldKind::Gradient : ir::FieldKind::Noise;
    auto a = vectorArg(*args.values[0], sig.args[0], e.name);
    auto b = vectorArg(*args.values[1], sig.args[1], e.name);
    if (!a || !b) return {};
    f->a = *a;
    f->b = *b;
    auto num = [&](size_t i, double fallback) -> std::optional<Scalar> {
      if (i >= sig.args.size() || !args.values[i]) return ir::constant(fallback);
      return numberArg(*args.values[i], sig.args[i], e.name);
    };
    if (f->kind == ir::FieldKind::Stripes || f->kind == ir::FieldKind::Gradient) {
      if (args.values[2]) {
        auto axis = vectorArg(*args.values[2], sig.args[2], e.name);
        if (!axis) return {};
        f->axis = glm::normalize(axis->value());
      } else {
        f->axis = f->kind == ir::FieldKind::Stripes ? dvec3(1, 0, 0) : dvec3(0, 1, 0);
      }
    }
    switch (f->kind) {
      case ir::FieldKind::Checker: {
        auto size = num(2, 1);
        if (!size) return {};
        f->size = *size;
        break;
      }
      case ir::FieldKind::Stripes: {
        auto period = num(3, 1);
        if (!period) return {};
        f->size = *period;
        break;
      }
      case ir::FieldKind::Gradient: {
        auto from = num(3, 0), to = num(4, 1);
        if (!from || !to) return {};
        if (from->isConst() && to->isConst() && from->value == to->value) {
          diags_->error(args.values[4] ? args.values[4]->range : e.range,
                        "'from' and 'to' of 'gradient' must differ, both are " + fmt(from->value));
          return {};
        }
        f->from = *from;
        f->to = *to;
        break;
      }
      case ir::FieldKind::Noise: {
        auto scale = num(2, 1), octaves = num(3, 4);
        if (!scale || !octaves) return {};
        const double n = octaves->value;
        if (n != std::floor(n) || n < 1 || n > 8) {
          diags_->error(args.values[3]->range, "'octaves' of 'noise' must be a whole number from 1 to 8, got " + fmt(n));
          return {};
        }
        f->size = *scale;
        f->octaves = static_cast<int>(n);
        break;
      }
      case ir::FieldKind::Texture: break;  // evalTexture
    }
    Value v;
    v.type = Value::Type::Field;
    v.field = f;
    v.range = e.range;
    return v;
  }

  // ---- statements --------------------------------------------------------

  void checkScene(const ast::Expr& e) {
    if (!e.arguments.empty()) diags_->error(e.arguments[0].name_range, "'scene' takes no arguments");
    if (!e.has_block) {
      diags_->error(e.range, "'scene' needs a block: 'scene { ... }'");
      return;
    }
    std::vector<ir::NodeRef> children;
    for (const ast::ExprPtr& c : e.children) {
      Value v = evalExpr(*c);
      if (v.type == Value::Type::Error) continue;
      if (v.type != Value::Type::Shape) {
        diags_->error(v.range, std::string("the scene holds shapes, not ") + reported(v));
        continue;
      }
      children.push_back(v.shape);
    }
    if (children.empty()) {
      if (!diags_->hasErrors()) diags_->error(e.range, "the scene is empty");
      return;
    }
    auto root = std::make_shared<ir::Node>();
    root->kind = ir::NodeKind::Union;
    root->range = e.range;
    root->children = std::move(children);
    scene_.root = root;
  }

  // sky(map: "studio.exr"): the file is read, and refused with its reason
  // (missing, unreadable, not 2:1, a texel not a finite non-negative radiance).
  void checkSkyMap(const ast::Argument& a, double rotation, double strength) {
    const ast::Expr& name = *a.value;
    if (name.kind != ast::ExprKind::String) {
      diags_->error(name.range, "'map' of 'sky' must be a string naming an EXR or Radiance HDR image, as in "
                                "sky(map: \"studio.exr\")");
      return;
    }
    const std::string path = resolveBesides(name.range.file ? name.range.file->path : source_.path, name.name);
    scene_.data_files.push_back(path);
    EnvMapFile map = readEnvMapFile(path);
    if (!map.image) {
      std::error_code ignored;
      const std::string tried = std::filesystem::absolute(path, ignored).lexically_normal().string();
      diags_->error(name.range, "cannot use '" + name.name + "' as an environment map: " + map.reason +
                                    " (looked for '" + tried + "')");
      return;
    }
    scene_.sky.map = std::move(map.image);
    scene_.sky.rotation_degrees = rotation;
    scene_.sky.strength = strength;
  }

  void checkSetting(const ast::Expr& e) {
    const BuiltinSignature& sig = *findBuiltin(e.name);
    if (e.has_block) diags_->error(e.range, "'" + e.name + "' takes no block");
    if (e.name != "light" && !seen_settings_.insert(e.name).second)
      diags_->warning(e.name_range, "setting-again", "'" + e.name + "' is set again; the last one wins");
    // a failed one: the others are still checked
    BoundArgs args = bindArguments(e, sig.args, false, e.name == "sky" ? "map" : nullptr);
    auto vec = [&](size_t i) -> std::optional<dvec3> {
      if (!args.values[i]) return std::nullopt;
      auto v = vectorArg(*args.values[i], sig.args[i], e.name);
      return v ? std::optional<dvec3>(v->value()) : std::nullopt;
    };
    auto num = [&](size_t i) -> std::optional<double> {
      if (!args.values[i]) return std::nullopt;
      auto s = numberArg(*args.values[i], sig.args[i], e.name);
      return s ? std::optional<double>(s->value) : std::nullopt;
    };
    auto whole = [&](size_t i, int lo, int hi, int& out) {
      auto v = num(i);
      if (!v) return;
      if (*v != std::floor(*v) || *v < lo || *v > hi) {
        diags_->error(args.values[i]->range, "'" + std::string(sig.args[i].name) + "' must be a whole number from " +
                                                std::to_string(lo) + " to " + std::to_string(hi) +
                                                ", got " + fmt(*v));
        return;
      }
      out = static_cast<int>(*v);
    };
    if (e.name == "camera") {
      ir::Camera& c = scene_.camera;
      if (auto v = vec(0)) c.position = *v;
      if (auto v = vec(1)) c.target = *v;
      if (auto v = vec(2)) c.up = *v;
      if (auto v = num(3)) {
        if (*v <= 0 || *v >= 180) {
          diags_->error(args.values[3]->range, "'fov' must be between 0 and 180 degrees, got " + fmt(*v));
        } else {
          c.fov_degrees = *v;
        }
      }
      if (auto v = num(4)) c.aperture = *v;
      if (auto v = num(5)) c.focus_distance = *v;
      if (glm::length(c.target - c.position) == 0)
        diags_->error(e.range, "the camera's 'target' equals its 'position'");
      else if (glm::length(glm::cross(c.target - c.position, c.up)) < 1e-9)
        diags_->error(e.range, "the camera's 'up' is parallel to its view direction");
    } else if (e.name == "render") {
      ir::RenderSettings& r = scene_.render;
      if (args.values[0]) {
        const Value& size = *args.values[0];
        if (size.type != Value::Type::Vector || size.vector.size() != 2 || !size.vector[0].isConst() ||
            !size.vector[1].isConst()) {
          diags_->error(size.range, "'size' of 'render' must be [width, height]");
        } else {
          const double w = size.vector[0].value, h = size.vector[1].value;
          if (w != std::floor(w) || h != std::floor(h) || w < 1 || h < 1 || w > kMaxImageSide ||
              h > kMaxImageSide)
            diags_->error(size.range, "'size' must be whole numbers from 1 to " +
                                         std::to_string(kMaxImageSide));
          else
            r.width = static_cast<int>(w), r.height = static_cast<int>(h);
        }
      }
      whole(1, 1, kMaxSamples, r.spp);
      if (args.values[1]) r.spp_given = true;
      whole(2, 0, kMaxBounces, r.bounces);
      whole(3, 0, 16, r.light_samples);
    } else if (e.name == "sky") {
      auto color = vec(0), top = vec(1), bottom = vec(2);
      if (color && (top || bottom)) diags_->error(e.range, "'sky' takes 'color', or 'top' and 'bottom'");
      if (args.file && (color || top || bottom))
        diags_->error(args.file->name_range, "'sky' takes 'map', or colours ('color', 'top', 'bottom'), not both");
      if (color) scene_.sky.top = scene_.sky.bottom = *color;
      if (top) scene_.sky.top = *top;
      if (bottom) scene_.sky.bottom = *bottom;
      const auto rotation = num(4), strength = num(5);
      if (!args.file && (rotation || strength))
        diags_->error(args.values[rotation ? 4 : 5]->range, std::string("'") + (rotation ? "rotation" : "strength") +
                                                                "' of 'sky' applies to a map: sky(map: \"studio.exr\", ...)");
      if (args.file) checkSkyMap(*args.file, rotation.value_or(0), strength.value_or(1));
    } else if (e.name == "sun") {
      ir::Sun s;
      if (auto v = vec(0)) s.direction = glm::normalize(*v);
      if (auto v = num(1)) {
        if (*v > 45) diags_->error(args.values[1]->range, "'angle' of 'sun' must be at most 45 degrees");
        s.angle_degrees = *v;
      }
      const dvec3 color = vec(2).value_or(dvec3(1));
      const double strength = num(3).value_or(3);
      // Strength is the irradiance the sun gives a surface facing it; the
      // disc's radiance follows from its solid angle 2*pi*(1 - cos(angle)).
      const double solid_angle = 2 * M_PI * (1 - std::cos(glm::radians(std::max(s.angle_degrees, 0.05))));
      s.radiance = color * strength / solid_angle;
      scene_.sun = s;
    } else if (e.name == "light") {
      if (scene_.lights.size() >= static_cast<size_t>(kMaxLights)) {
        diags_->error(e.name_range, "a scene has at most " + std::to_string(kMaxLights) +
                                       " 'light's (the kernel's per-ray light loop is bounded); this is light " +
                                       std::to_string(scene_.lights.size() + 1));
        return;
      }
      ir::SphereLight l;
      if (auto v = vec(0)) l.position = *v;
      if (auto v = num(1)) l.radius = *v;
      const dvec3 color = vec(2).value_or(dvec3(1));
      const double strength = num(3).value_or(10);
      l.radiance = color * strength;
      scene_.lights.push_back(l);
    }
  }
};

}  // namespace

ir::Scene check(const ast::File& file, const SourceFile& source, Diagnostics& diags,
                const CheckOptions& options) {
  Checker checker(source, diags, options);
  return checker.run(file);
}

}  // namespace sdfc
