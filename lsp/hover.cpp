// Hover: a built-in's signature and parameters from the catalogue; for a
// shape in the scene, whether the compiled node is an exact distance or a
// bound, its Lipschitz factor, and the reason.
#include <cstdio>
#include <functional>

#include "lsp/catalogue.h"
#include "lsp/features.h"
#include "passes/deform.h"

namespace sdfc::lsp {
namespace {

// Why analysis (passes/analyze.cpp) marks this node as a bound.
std::string whyBound(const ir::Node& n) {
  for (const ir::NodeRef& c : n.children)
    if (!c->exact) return "a child is itself a bound";
  switch (n.kind) {
    case ir::NodeKind::Primitive:
      if (n.primitive == PrimitiveKind::Torus) return "the minor radius can exceed the major radius";
      if (n.primitive == PrimitiveKind::Ellipsoid) return "an ellipsoid has no closed-form distance; this is |p / radii| - 1 scaled by the smallest radius";
      return "this primitive's formula is a bound";
    case ir::NodeKind::Union:
    case ir::NodeKind::Intersect:
    case ir::NodeKind::Subtract:
      if (!n.smooth.isConst() || n.smooth.value > 0) return "a smooth blend lowers the distance";
      return n.kind == ir::NodeKind::Intersect ? "max() of exact distances is a bound inside the corners"
                                               : "subtraction (max(a, -b)) is a bound near the cut";
    case ir::NodeKind::ScaleNonUniform: return "a non-uniform scale stretches distances (min factor used)";
    case ir::NodeKind::Reflect: return "the shape crosses the mirror plane";
    case ir::NodeKind::Repeat: return "the copies overlap (a union: a bound inside), or more cells than are checked hold them";
    case ir::NodeKind::Morph: return "a blend of two distance fields is not a distance";
    case ir::NodeKind::Revolve: return "the profile reaches across the axis (x < -offset)";
    case ir::NodeKind::Twist: {
      char buf[160];
      std::snprintf(buf, sizeof buf, "a twist stretches space by up to %.4g within radius %.4g of the axis; "
                                     "the distance is divided by that, and outside it is the bounding cylinder's",
                    n.deform_lipschitz, deformReach(n));
      return buf;
    }
    case ir::NodeKind::Bend: {
      char buf[160];
      std::snprintf(buf, sizeof buf, "a bend stretches space by up to %.4g within radius %.4g of the axis; "
                                     "the distance is divided by that, and outside it is the bounding cylinder's",
                    n.deform_lipschitz, deformReach(n));
      return buf;
    }
    case ir::NodeKind::Displace: {
      char buf[160];
      std::snprintf(buf, sizeof buf, "noise displacement stretches the field by up to %.4g; the distance is "
                                     "divided by that", n.deform_lipschitz);
      return buf;
    }
    case ir::NodeKind::RepeatPolar: return "the copies overlap (a union: a bound inside), or more sectors than are checked hold them";
    default: return "a transform of a bound";
  }
}

std::string nodeText(const Analysis& a, const ir::Node& n) {
  // After a checker error the analysis passes do not run, and every node keeps
  // its defaults (exact, factor 1): say nothing rather than something false.
  if (a.diagnostics.hasErrors())
    return "\n**This node:** exactness is not known until the scene's errors are fixed.\n";
  char buf[64];
  std::snprintf(buf, sizeof buf, "%g", n.lipschitz);
  if (n.exact) return "\n**This node:** exact Euclidean distance (Lipschitz factor " + std::string(buf) + ").\n";
  return "\n**This node:** a distance bound, not exact: " + whyBound(n) + " (Lipschitz factor " + buf +
         "; marching scales steps by its inverse).\n";
}

struct Found {
  const ast::Expr* call = nullptr;        // a callee name under the cursor
  const ast::Expr* arg_owner = nullptr;   // the call whose argument name is under the cursor
  const ast::Argument* arg = nullptr;
  const ast::Expr* name = nullptr;        // a bare name (time, pi)
};

void find(const ast::Expr& e, size_t offset, Found& f) {
  auto within = [&](const SourceRange& r) { return r.file && r.begin <= offset && offset <= r.end; };
  if (e.kind == ast::ExprKind::Call && within(e.name_range)) f.call = &e;
  if (e.kind == ast::ExprKind::Name && within(e.range)) f.name = &e;
  for (const ast::Argument& a : e.arguments) {
    if (!a.name.empty() && within(a.name_range)) {
      f.arg_owner = &e;
      f.arg = &a;
    }
    if (a.value) find(*a.value, offset, f);
  }
  for (const ast::ExprPtr& o : e.operands) find(*o, offset, f);
  for (const ast::ExprPtr& c : e.children) find(*c, offset, f);
}

json result(const Analysis& a, const SourceRange& r, const std::string& markdown) {
  return {{"contents", {{"kind", "markdown"}, {"value", markdown}}},
          {"range", a.lines.rangeOf(r.begin, r.end)}};
}

}  // namespace

json hover(const Analysis& a, size_t offset) {
  if (const NameUse* use = a.nameAt(offset)) {
    if (use->scope) {
      const CalleeDoc* c = a.callee(use->scope->name);
      for (const ParamDoc& p : c ? c->params : std::vector<ParamDoc>{})
        if (p.name == use->name)
          return result(a, use->range, "```sdf\n" + p.label() + "\n```\nparameter of `" + c->name + "`: " + p.type +
                                           (p.required ? ", required" : ", default " + p.fallback) + "\n");
      return nullptr;
    }
    if (!a.lets.count(use->name)) {
      // Imported: its definition as its own file has it (hover was null here).
      const auto it = a.imported_docs.find(a.importedKey(use->name));
      if (it == a.imported_docs.end()) return nullptr;
      const Analysis::ImportedDoc& d = it->second;
      CalleeDoc callee = d.callee;
      callee.name = use->name;  // as this file calls it ("l.tower")
      std::string md = d.parametric ? callee.markdown() + "\n" : std::string();
      md += "```sdf\n" + d.text + "\n```\n";
      if (!d.parametric) md += "imported from '" + d.file + "'\n";
      return result(a, use->range, md);
    }
    const ast::Statement* s = a.lets.at(use->name);
    std::string value = a.text().substr(s->range.begin, s->range.end - s->range.begin);
    if (value.size() > 400) value = value.substr(0, 400) + " ...";
    std::string md = "```sdf\n" + value + "\n```\n";
    if (auto d = a.definitions.find(use->name); d != a.definitions.end()) md = d->second.markdown() + "\n" + md;
    if (const ir::Node* n = a.definitionNode(use->name)) md += nodeText(a, *n);
    return result(a, use->range, md);
  }
  Found f;
  for (const ast::Statement& s : a.tree.statements)
    if (s.value) find(*s.value, offset, f);
  if (f.arg) {
    const CalleeDoc* c = a.callee(f.arg_owner->name);
    if (!c) return nullptr;
    for (const ParamDoc& p : c->params)
      if (p.name == f.arg->name) {
        std::string md = "```sdf\n" + p.label() + "\n```\nparameter of `" + c->name + "`: " + p.type;
        if (!p.rule.empty()) md += ", " + p.rule;
        md += p.required ? ", required" : (p.fallback.empty() ? ", optional" : ", default " + p.fallback);
        if (!p.time_allowed) md += "; constant (cannot use `time`)";
        return result(a, f.arg->name_range, md + "\n");
      }
    return nullptr;
  }
  if (f.call) {
    const CalleeDoc* c = a.callee(f.call->name);
    if (!c) return nullptr;
    std::string md = c->markdown();
    auto it = a.nodes.find(f.call->range.begin);
    if (it != a.nodes.end()) md += nodeText(a, *it->second);
    return result(a, f.call->name_range, md);
  }
  if (f.name) {
    if (f.name->name == "time") return result(a, f.name->range, "`time`: scene time in seconds (`--time T`, `--frames`)\n");
    if (f.name->name == "pi") return result(a, f.name->range, "`pi` = 3.14159265358979\n");
    if (const CalleeDoc* c = findCallee(f.name->name)) return result(a, f.name->range, c->markdown());
  }
  return nullptr;
}

}  // namespace sdfc::lsp
