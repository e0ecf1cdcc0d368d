#!/usr/bin/env python3
"""The crate's layers, checked: no file imports from a layer above its own, and no two files
import each other, directly or through others.

usage: python3 .ci/layers.py [--root DIR] [--graph]

The layer order is read from the section "## Layers" of docs/architecture.md: each numbered
item names, in backticks before its first colon, the top-level modules of one layer, bottom
first. Every top-level module of src/ must be in exactly one layer.

What counts as an import of file A from file B: a `use` declaration in A (`crate::`, `super::`,
`self::` or a child module of A; `pub use` re-exports are followed, not counted, in the circle
check, and an upward one is still refused), a qualified path in A's code (`crate::a::b`,
`super::x`, `child::x`), and the path of a serde `serialize_with`/`deserialize_with`/`with`
attribute. Comments, string contents and `#[cfg(test)]` items (and files declared by a
`#[cfg(test)] mod x;`) are left out. Each path is resolved to the file that defines the item it
names: through `mod.rs` files, `use` and `pub use` re-exports (globs too), so a name
re-exported by a higher module still counts as a use of the file that defines it. `src/lib.rs`,
the crate root that declares and re-exports every module, has no layer.

Exit status 1, with the file, line and names of each offence, on an import from a lower layer
to a higher one or a circle between files; 0 otherwise. `--graph` prints the imports between
top-level modules.
"""

import os
import re
import sys
from collections import defaultdict

ITEM = re.compile(
    r"\b(?:(?:const|async|unsafe)\s+)*(?:fn|struct|enum|trait|type|const|static(?:\s+mut)?|union)"
    r"\s+(\w+)|\bmacro_rules!\s*(\w+)"
)
USE = re.compile(r"\b((?:pub(?:\s*\([^)]*\))?\s+)?)use\s+([^;]*);")
QUALIFIED = re.compile(r"(?<![\w:])((?:crate|super|self)(?:\s*::\s*\w+)+)")
SERDE_PATH = re.compile(r"\b(?:serialize_with|deserialize_with|with)\s*=\s*\"([\w:]+)\"")
CFG_TEST = re.compile(r"#\[cfg\(test\)\]")
RAW = re.compile(r'b?r(#*)"')
CHAR = re.compile(r"'(?:\\(?:u\{[0-9a-fA-F]+\}|x[0-9a-fA-F]{2}|.)|[^\\'\n])'")


def blank(text):
    """Comments and the contents of string and char literals replaced by spaces (newlines
    kept, so offsets keep their lines); serde attribute paths are returned apart, with their
    offsets, since they live inside strings."""
    out = list(text)
    serde = [(m.start(), m.group(1)) for m in SERDE_PATH.finditer(text)]
    i, n = 0, len(text)

    def wipe(a, b):
        for k in range(a, b):
            if out[k] != "\n":
                out[k] = " "

    while i < n:
        c = text[i]
        if text.startswith("//", i):
            j = text.find("\n", i)
            j = n if j < 0 else j
            wipe(i, j)
            i = j
        elif text.startswith("/*", i):
            depth, j = 1, i + 2
            while j < n and depth:
                if text.startswith("/*", j):
                    depth, j = depth + 1, j + 2
                elif text.startswith("*/", j):
                    depth, j = depth - 1, j + 2
                else:
                    j += 1
            wipe(i, j)
            i = j
        elif c in "br" and not (i and (text[i - 1].isalnum() or text[i - 1] == "_")) and RAW.match(
            text, i
        ):
            m = RAW.match(text, i)
            close = '"' + m.group(1)
            j = text.find(close, m.end())
            j = n if j < 0 else j + len(close)
            wipe(m.end(), j - len(close))
            i = j
        elif c == '"':
            j = i + 1
            while j < n and text[j] != '"':
                j += 2 if text[j] == "\\" else 1
            wipe(i + 1, j)
            i = j + 1
        elif c == "'":
            m = CHAR.match(text, i)
            if m:
                wipe(i + 1, m.end() - 1)
                i = m.end()
            else:
                i += 1  # a lifetime or a label
        else:
            i += 1
    return "".join(out), serde


def matching_brace(text, i):
    """The offset after the brace that closes the one at `i`."""
    depth = 0
    for j in range(i, len(text)):
        if text[j] == "{":
            depth += 1
        elif text[j] == "}":
            depth -= 1
            if depth == 0:
                return j + 1
    return len(text)


def without_test_items(text):
    """`#[cfg(test)]` items blanked; the names of the test-only child modules declared."""
    test_children = set()
    out = text
    for m in reversed(list(CFG_TEST.finditer(text))):
        j = m.end()
        # Further attributes, then the item: up to its `;` or its closing brace.
        while True:
            a = re.match(r"\s*#\[", text[j:])
            if not a:
                break
            j = matching_bracket(text, j + a.end() - 1)
        decl = re.match(r"\s*(?:pub(?:\s*\([^)]*\))?\s+)?mod\s+(\w+)\s*;", text[j:])
        if decl:
            test_children.add(decl.group(1))
        semi, brace = text.find(";", j), text.find("{", j)
        if brace >= 0 and (semi < 0 or brace < semi):
            end = matching_brace(text, brace)
        else:
            end = semi + 1 if semi >= 0 else len(text)
        out = out[: m.start()] + re.sub(r"[^\n]", " ", out[m.start() : end]) + out[end:]
    return out, test_children


def matching_bracket(text, i):
    depth = 0
    for j in range(i, len(text)):
        if text[j] == "[":
            depth += 1
        elif text[j] == "]":
            depth -= 1
            if depth == 0:
                return j + 1
    return len(text)


def split_tree(tree):
    """A use tree as (path, bound name) pairs: `a::{b, c::{d as e, *}}` ->
    [(['a', 'b'], 'b'), (['a', 'c', 'd'], 'e'), (['a', 'c', '*'], None)]."""
    tree = re.sub(r"\s+", " ", tree).strip()
    m = re.match(r"^(.*?)\{(.*)\}$", tree)
    if not m:
        alias = None
        if " as " in tree:
            tree, alias = (s.strip() for s in tree.split(" as ", 1))
        path = [s.strip() for s in tree.split("::") if s.strip()]
        if path and path[-1] == "self":
            path = path[:-1]
        if not path:
            return []
        return [(path, alias or (None if path[-1] == "*" else path[-1]))]
    head = [s.strip() for s in m.group(1).split("::") if s.strip()]
    parts, depth, cur = [], 0, ""
    for ch in m.group(2):
        if ch == "{":
            depth += 1
        elif ch == "}":
            depth -= 1
        if ch == "," and depth == 0:
            parts.append(cur)
            cur = ""
        else:
            cur += ch
    parts.append(cur)
    out = []
    for part in parts:
        if part.strip():
            for path, alias in split_tree(part):
                out.append((head + path, alias))
            if part.strip() == "self":
                out.append((head, head[-1] if head else None))
    return out


class File:
    def __init__(self, module, path, text):
        self.module = module
        self.path = path
        code, self.serde = blank(text)
        self.code, self.test_children = without_test_items(code)
        self.lines = [0] + [i for i, c in enumerate(self.code) if c == "\n"]
        self.children = set(re.findall(r"\bmod\s+(\w+)\s*[;{]", self.code))
        self.defs = set()
        depth = 0
        spans = []
        for m in re.finditer(r"[{}]|" + ITEM.pattern, self.code):
            if m.group(0) == "{":
                depth += 1
            elif m.group(0) == "}":
                depth -= 1
            elif depth == 0:
                self.defs.add(m.group(1) or m.group(2))
        # Every `use` path with its line and whether it is a re-export; the names it binds
        # (name -> absolute path) and its globs, for resolving paths through this file.
        self.bound, self.globs, self.uses = {}, [], []
        for m in USE.finditer(self.code):
            spans.append((m.start(), m.end()))
            public = bool(m.group(1).strip())
            line = self.line_of(m.start())
            for path, alias in split_tree(m.group(2)):
                absolute = self.absolute(path)
                if absolute is None:
                    continue
                self.uses.append((absolute, line, public))
                if path[-1] == "*":
                    self.globs.append(absolute[:-1])
                elif alias and alias != "_":
                    self.bound[alias] = absolute
        # Qualified paths in code, outside `use` declarations; serde attribute paths.
        self.paths = []
        outside = self.code
        for a, b in spans:
            outside = outside[:a] + re.sub(r"[^\n]", " ", outside[a:b]) + outside[b:]
        for m in QUALIFIED.finditer(outside):
            path = [s.strip() for s in m.group(1).split("::")]
            self.paths.append((self.absolute(path), self.line_of(m.start())))
        if self.children:
            names = "|".join(sorted(self.children))
            child = re.compile(r"(?<![\w:])(" + names + r")\s*::\s*(\w+)")
            for m in child.finditer(outside):
                path = list(module) + [m.group(1), m.group(2)]
                self.paths.append((path, self.line_of(m.start())))
        for offset, text_path in self.serde:
            self.paths.append((self.absolute(text_path.split("::")), self.line_of(offset)))

    def line_of(self, offset):
        lo, hi = 0, len(self.lines)
        while lo + 1 < hi:
            mid = (lo + hi) // 2
            if self.lines[mid] < offset:
                lo = mid
            else:
                hi = mid
        return lo + 1

    def absolute(self, path):
        """A path as seen from this file, from the crate root; None for other crates."""
        if not path:
            return None
        if path[0] == "crate":
            return path[1:]
        if path[0] == "self":
            return list(self.module) + path[1:]
        if path[0] == "super":
            base = list(self.module)
            while path and path[0] == "super":
                base, path = base[:-1], path[1:]
            return base + path
        if path[0] in self.children:
            return list(self.module) + path
        return None


class Crate:
    def __init__(self, src):
        self.src = src
        self.files = {}
        for root, _, names in os.walk(src):
            for name in sorted(names):
                if not name.endswith(".rs"):
                    continue
                path = os.path.join(root, name)
                parts = os.path.relpath(path, src)[:-3].split(os.sep)
                if parts[-1] in ("mod", "lib"):
                    parts = parts[:-1]
                shown = os.path.relpath(path, os.path.dirname(os.path.normpath(src)))
                with open(path, encoding="utf-8") as f:
                    self.files[tuple(parts)] = File(tuple(parts), shown, f.read())
        # Files declared by `#[cfg(test)] mod x;` (and everything below them) are tests.
        tests = {m + (c,) for m, f in self.files.items() for c in f.test_children}
        for module in list(self.files):
            if any(module[: len(t)] == t for t in tests):
                del self.files[module]

    def resolve(self, path, seen=None):
        """The files that define what the absolute `path` names, each with the name."""
        seen = set() if seen is None else seen
        key = tuple(path)
        if key in seen:
            return set()
        seen.add(key)
        module = ()
        for i, segment in enumerate(path):
            if module + (segment,) in self.files:
                if i + 1 == len(path) and segment in self.files[module].defs:
                    # The last segment names both a child module and an item (`fn x`, `mod x`).
                    return {(module, segment), (module + (segment,), "(module)")}
                module += (segment,)
                continue
            if segment == "*":
                return {(module, "*")}
            f = self.files[module]
            found = set()
            if segment in f.defs:
                found.add((module, segment))
            if segment in f.bound:
                found |= self.resolve(f.bound[segment] + path[i + 1 :], seen)
            if not found:
                for glob in f.globs:
                    found |= self.resolve(glob + path[i:], seen)
            return found or {(module, segment)}
        return {(module, "(module)")}

    def imports(self):
        """(from, to, name, line, is a re-export) for every import between two files."""
        out = []
        for module, f in self.files.items():
            refs = [(p, line, public) for p, line, public in f.uses]
            refs += [(p, line, False) for p, line in f.paths if p is not None]
            for path, line, public in refs:
                if path and path[-1] == "*":
                    path = path[:-1]
                for target, name in self.resolve(path):
                    if target != module and target in self.files:
                        out.append((module, target, name, line, public))
        return out


def read_layers(architecture):
    with open(architecture, encoding="utf-8") as f:
        text = f.read()
    section = re.search(r"^## Layers\n(.*?)(?=^## |\Z)", text, re.S | re.M)
    if not section:
        sys.exit(f"{architecture}: no section '## Layers'")
    layers = []
    for line in section.group(1).splitlines():
        m = re.match(r"^\d+\.\s+(.*?):", line)
        if m:
            layers.append(re.findall(r"`(\w+)`", m.group(1)))
    return layers


def circles(nodes, edges):
    """Strongly connected groups of more than one file (Tarjan, iterative)."""
    index, low, on, stack, found, counter = {}, {}, set(), [], [], [0]
    for start in nodes:
        if start in index:
            continue
        work = [(start, iter(sorted(edges.get(start, ()))))]
        index[start] = low[start] = counter[0]
        counter[0] += 1
        stack.append(start)
        on.add(start)
        while work:
            v, children = work[-1]
            advanced = False
            for w in children:
                if w not in index:
                    index[w] = low[w] = counter[0]
                    counter[0] += 1
                    stack.append(w)
                    on.add(w)
                    work.append((w, iter(sorted(edges.get(w, ())))))
                    advanced = True
                    break
                if w in on:
                    low[v] = min(low[v], index[w])
            if advanced:
                continue
            work.pop()
            if work:
                low[work[-1][0]] = min(low[work[-1][0]], low[v])
            if low[v] == index[v]:
                group = []
                while True:
                    w = stack.pop()
                    on.discard(w)
                    group.append(w)
                    if w == v:
                        break
                if len(group) > 1:
                    found.append(sorted(group))
    return found


def main():
    args = sys.argv[1:]
    root = "."
    if "--root" in args:
        root = args[args.index("--root") + 1]
    crate = Crate(os.path.join(root, "src"))
    layers = read_layers(os.path.join(root, "docs", "architecture.md"))
    rank = {}
    for level, names in enumerate(layers):
        for name in names:
            if name in rank:
                print(f"docs/architecture.md: `{name}` is in two layers")
                return 1
            rank[name] = level
    failed = False
    tops = sorted({m[0] for m in crate.files if m})
    for top in tops:
        if top not in rank:
            print(f"src/{top}: module `{top}` is in no layer of docs/architecture.md")
            failed = True
    for name in sorted(set(rank) - set(tops)):
        print(f"docs/architecture.md: layer names `{name}`, no module of src/")
        failed = True
    imports = crate.imports()
    if "--graph" in args:
        graph = defaultdict(set)
        for a, b, _, _, _ in imports:
            if a and b and a[0] != b[0]:
                graph[a[0]].add(b[0])
        for top in tops:
            print(f"{top}: {', '.join(sorted(graph[top]))}")
    path = lambda m: crate.files[m].path
    upward = defaultdict(set)
    for a, b, name, line, _ in imports:
        if a and b and a[0] in rank and b[0] in rank and rank[a[0]] < rank[b[0]]:
            upward[(path(a), line, path(b), a[0], b[0])].add(name)
    for (source, line, target, low, high), names in sorted(upward.items()):
        print(
            f"{source}:{line}: layer `{low}` uses {', '.join(sorted(names))} of {target}, "
            f"in layer `{high}` above it"
        )
        failed = True
    edges, why = defaultdict(set), defaultdict(set)
    for a, b, name, line, public in imports:
        if not public:
            edges[a].add(b)
            why[(a, b)].add((line, name))
    for n, group in enumerate(circles(sorted(crate.files), edges), 1):
        failed = True
        print(f"circle {n} between {len(group)} files:")
        members = set(group)
        for a in group:
            for b in sorted(edges[a] & members):
                lines = sorted(why[(a, b)])
                names = ", ".join(sorted({name for _, name in lines}))
                at = ", ".join(str(line) for line in sorted({line for line, _ in lines}))
                print(f"  {path(a)}:{at} -> {path(b)}: {names}")
    if failed:
        return 1
    print(f"layers: {len(crate.files)} files in {len(layers)} layers, no upward import, no circle")
    return 0


if __name__ == "__main__":
    sys.exit(main())
