#!/usr/bin/env python3
"""Checks the house rules of crates/grains/src against ARCHITECTURE.md.

- No source file over 800 lines; runner/ at most 2,500 lines in all.
- No module imports one in a layer above its own, the layers being those
  of the numbered block under "## The layers" in ARCHITECTURE.md (each line:
  number, name, then the top-level modules of that layer).
- No two files import each other, a directory module's `mod.rs` and the
  files under it excepted (the façade re-exports its parts, and the parts
  use the types it defines).

Breaches listed under "## Known breaches" in ARCHITECTURE.md (one bullet,
the breach's text in backticks) are printed but do not fail the check.

Imports are the paths a file names outside its `#[cfg(test)]` modules:
`crate::a::b`, `super::x`, `self::x`, and in a `mod.rs` (or lib.rs) a child
module's name; each resolves to the file of its longest prefix that is a
module. Exit status 1 with one line per breach.

    tools/check_layers.py            # from anywhere in the repository
"""
import os
import re
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SRC = os.path.join(ROOT, "crates", "grains", "src")
MAX_FILE = 800
MAX_RUNNER = 2500


def layers():
    """Top-level module -> layer number, from ARCHITECTURE.md."""
    text = open(os.path.join(ROOT, "ARCHITECTURE.md")).read()
    block = text.split("## The layers", 1)[1].split("```", 2)[1]
    out = {}
    for line in block.splitlines():
        m = re.match(r"\s*(\d+)\s+\S+\s+(.*)", line)
        if not m:
            continue
        items = re.sub(r"\([^)]*\)", "", m.group(2))
        for item in items.split(","):
            name = item.strip().split("/")[0].split(" ")[0]
            if name:
                out[name] = int(m.group(1))
    return out


def module_of(path):
    """The module path of a source file: ['runner', 'dsmc'] for runner/dsmc.rs."""
    rel = os.path.relpath(path, SRC)[:-3].split(os.sep)
    if rel[-1] in ("mod", "lib"):
        rel = rel[:-1]
    return rel


def file_of(mod):
    """The file that defines a module path, or None."""
    base = os.path.join(SRC, *mod) if mod else os.path.join(SRC, "lib")
    for cand in (base + ".rs", os.path.join(base, "mod.rs")):
        if os.path.isfile(cand):
            return cand
    return None


def strip(text):
    """The text without comments, strings and #[cfg(test)] modules."""
    text = re.sub(r"#\[cfg\(test\)\]\s*(pub(\([^)]*\))?\s+)?mod\s+\w+\s*\{.*", "", text, flags=re.S)
    text = re.sub(r"//[^\n]*", "", text)
    text = re.sub(r'"(\\.|[^"\\])*"', '""', text)
    return text


def imports(path, mod, children):
    """The files that the file `path` (module `mod`) names."""
    text = strip(open(path).read())
    is_dir_module = os.path.basename(path) in ("mod.rs", "lib.rs")
    found = set()
    # `use a::{b, c::d}` groups name several paths: expand one level.
    paths = []
    # A `pub use` re-exports (the façade of a module); it is no dependency.
    for m in re.finditer(r"(?<!pub )(?<!pub\(crate\) )\buse\s+([^;]+);", text):
        body = re.sub(r"\s+", "", m.group(1))
        g = re.match(r"(.*?)::\{(.*)\}$", body)
        if g:
            for part in re.split(r",(?![^{]*\})", g.group(2)):
                paths.append(g.group(1) + "::" + part)
        else:
            paths.append(body)
    code = re.sub(r"\bpub(\([^)]*\))?\s+use\s+[^;]+;", "", text)
    paths += re.findall(r"\b((?:crate|super|self)(?:::\w+)+)", code)
    if is_dir_module:
        paths += [c + "::x" for c in children if re.search(r"\b%s::" % c, text)]
    for p in paths:
        parts = [x for x in re.split(r"::", p) if x and not x.startswith("{")]
        if not parts:
            continue
        if parts[0] == "crate":
            target, parts = [], parts[1:]
        elif parts[0] == "super":
            target = list(mod)
            while parts and parts[0] == "super":
                target, parts = target[:-1], parts[1:]
        elif parts[0] == "self":
            target, parts = list(mod), parts[1:]
        elif is_dir_module and parts[0] in children:
            target = list(mod)
        else:
            continue
        best = file_of(target)
        for k in range(len(parts)):
            f = file_of(target + [re.sub(r"\W.*", "", x) for x in parts[: k + 1]])
            if f is None:
                break
            best = f
        if best and best != path:
            found.add(best)
    return found


def main():
    layer = layers()
    files = []
    for d, _, names in os.walk(SRC):
        files += [os.path.join(d, n) for n in names if n.endswith(".rs")]
    bad = []
    runner = 0
    for f in sorted(files):
        n = sum(1 for _ in open(f))
        rel = os.path.relpath(f, SRC)
        if n > MAX_FILE:
            bad.append(f"{rel}: {n} lines (at most {MAX_FILE})")
        if rel.startswith("runner" + os.sep):
            runner += n
    if runner > MAX_RUNNER:
        bad.append(f"runner/: {runner} lines in all (at most {MAX_RUNNER})")
    graph = {}
    for f in files:
        mod = module_of(f)
        d = os.path.dirname(f) if os.path.basename(f) in ("mod.rs", "lib.rs") else f[:-3]
        children = [n[:-3] if n.endswith(".rs") else n for n in os.listdir(d)] if os.path.isdir(d) else []
        graph[f] = imports(f, mod, children)
    for f, targets in sorted(graph.items()):
        me = module_of(f)
        rel = os.path.relpath(f, SRC)
        top = me[0] if me else None
        for t in sorted(targets):
            other = module_of(t)
            trel = os.path.relpath(t, SRC)
            if top and other and other[0] != top:
                if top not in layer or other[0] not in layer:
                    missing = top if top not in layer else other[0]
                    bad.append(f"{missing}: not in the layers of ARCHITECTURE.md")
                elif layer[other[0]] > layer[top]:
                    bad.append(
                        f"{rel} (layer {layer[top]}) imports {trel} (layer {layer[other[0]]})"
                    )
            family = is_parent(f, t) or is_parent(t, f)
            if f in graph.get(t, ()) and f < t and not family:
                bad.append(f"{rel} and {trel} import each other")
    known = known_breaches()
    bad = sorted(set(bad))
    new = [b for b in bad if b not in known]
    for b in bad:
        print(("known: " if b in known else "") + b)
    print(
        f"check_layers: {len(files)} files, runner/ {runner} lines, "
        f"{len(new)} breaches ({len(bad) - len(new)} known)"
    )
    return 1 if new else 0


def is_parent(a, b):
    """Whether file `a` is the mod.rs of a directory module holding `b`."""
    return os.path.basename(a) in ("mod.rs", "lib.rs") and b.startswith(os.path.dirname(a) + os.sep)


def known_breaches():
    """The breaches ARCHITECTURE.md lists under "## Known breaches"."""
    text = open(os.path.join(ROOT, "ARCHITECTURE.md")).read()
    if "## Known breaches" not in text:
        return set()
    part = text.split("## Known breaches", 1)[1].split("\n## ", 1)[0]
    return set(re.findall(r"^- `([^`]+)`", part, flags=re.M))


if __name__ == "__main__":
    sys.exit(main())
