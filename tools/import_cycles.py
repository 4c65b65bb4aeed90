"""Fail if the Python package or the Rust crates have an import cycle.

Usage::

    python tools/import_cycles.py          # exit status 1 and the cycles, if any

Python: a module of ``python/tubesweep`` depends on every module of the package it imports,
at the top or inside a function (a lazy import hides a cycle, it does not remove it); imports
under ``if TYPE_CHECKING:`` are left out. Importing a package (``from .surfaces import X``)
counts as importing its ``__init__``.

Rust: a module of a crate (one file) depends on every module its code names by a path
(``crate::a::b``, ``super::x``, ``tubesweep_core::a``, ``use`` lists and ``mod`` children aside);
comments and ``#[cfg(test)]`` modules are left out, so test fixtures may reach anywhere. A
``mod.rs`` that only declares and re-exports its children is the folder's table of contents:
its own dependencies are those re-exports, which never close a cycle through a child.

Cycles are the strongly connected components of more than one module (or a module naming
itself through a re-export), found with Tarjan's algorithm.
"""

from __future__ import annotations

import ast
import re
import sys
from pathlib import Path
from typing import Dict, Iterable, List, Set

ROOT = Path(__file__).resolve().parent.parent


def strongly_connected(graph: Dict[str, Set[str]]) -> List[List[str]]:
    index: Dict[str, int] = {}
    low: Dict[str, int] = {}
    stack: List[str] = []
    on: Set[str] = set()
    out: List[List[str]] = []

    def visit(v: str) -> None:
        index[v] = low[v] = len(index)
        stack.append(v)
        on.add(v)
        for w in sorted(graph.get(v, ())):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                on.discard(w)
                comp.append(w)
                if w == v:
                    break
            if len(comp) > 1:
                out.append(sorted(comp))

    sys.setrecursionlimit(10000)
    for v in sorted(graph):
        if v not in index:
            visit(v)
    return out


# ------------------------------------------------------------------------------------------ Python


def python_graph(package: Path) -> Dict[str, Set[str]]:
    name = package.name
    modules: Dict[str, Path] = {}
    for f in package.rglob("*.py"):
        parts = list(f.relative_to(package.parent).with_suffix("").parts)
        if parts[-1] == "__init__":
            parts = parts[:-1]
        modules[".".join(parts)] = f
    # compiled modules (their stubs name them) are leaves: they import nothing of the package
    leaves = {".".join(f.relative_to(package.parent).with_suffix("").parts) for f in package.rglob("*.pyi")}

    def resolve(target: str) -> Iterable[str]:
        if target in leaves:
            return
        while target and target not in modules:
            target = target.rpartition(".")[0]
        if target:
            yield target

    graph: Dict[str, Set[str]] = {m: set() for m in modules}
    for mod, f in modules.items():
        is_pkg = f.name == "__init__.py"
        here = mod if is_pkg else mod.rpartition(".")[0]
        tree = ast.parse(f.read_text(encoding="utf-8"))
        skip: Set[int] = set()
        for node in ast.walk(tree):
            if isinstance(node, ast.If) and "TYPE_CHECKING" in ast.unparse(node.test):
                skip.update(id(n) for b in node.body for n in ast.walk(b))
        for node in ast.walk(tree):
            if id(node) in skip:
                continue
            if isinstance(node, ast.Import):
                for a in node.names:
                    if a.name == name or a.name.startswith(name + "."):
                        graph[mod].update(resolve(a.name))
            elif isinstance(node, ast.ImportFrom):
                if node.level:
                    base = here
                    for _ in range(node.level - 1):
                        base = base.rpartition(".")[0]
                    base = f"{base}.{node.module}" if node.module else base
                elif node.module and (node.module == name or node.module.startswith(name + ".")):
                    base = node.module
                else:
                    continue
                for a in node.names:
                    sub = f"{base}.{a.name}"
                    graph[mod].update(resolve(sub if sub in modules or sub in leaves else base))
        graph[mod].discard(mod)
    return graph


# -------------------------------------------------------------------------------------------- Rust

_COMMENT = re.compile(r"//[^\n]*|/\*.*?\*/", re.S)
_STRING = re.compile(r'"(?:\\.|[^"\\])*"')
_PATH = re.compile(r"\b(crate|super|self|tubesweep_core)((?:::[A-Za-z_][A-Za-z0-9_]*)+)")
_USE_GROUP = re.compile(
    r"\b(crate|super|self|tubesweep_core)((?:::[A-Za-z_][A-Za-z0-9_]*)*)::\{([^{}]*(?:\{[^{}]*\}[^{}]*)*)\}"
)


def _strip_tests(code: str) -> str:
    """Drop `#[cfg(test)]` items (a `mod tests { … }` block or a `mod x;` line)."""
    out = []
    i = 0
    for m in re.finditer(r"#\[cfg\(test\)\]\s*(?:pub(?:\([a-z]+\))?\s+)?mod\s+\w+\s*([;{])", code):
        if m.start() < i:
            continue
        out.append(code[i : m.start()])
        if m.group(1) == ";":
            i = m.end()
            continue
        depth, j = 1, m.end()
        while depth and j < len(code):
            depth += {"{": 1, "}": -1}.get(code[j], 0)
            j += 1
        i = j
    out.append(code[i:])
    return "".join(out)


def rust_graph(crates: Dict[str, Path]) -> Dict[str, Set[str]]:
    """Modules named `crate_name::a::b`; edges to the longest existing module prefix of each path."""
    files: Dict[str, Path] = {}
    for cname, src in crates.items():
        for f in src.rglob("*.rs"):
            rel = f.relative_to(src).with_suffix("").parts
            if "tests" in rel or rel[-1].endswith("_tests") or rel[-1].startswith("test_"):
                continue  # test modules (declared under #[cfg(test)]) may reach anywhere
            if rel[-1] in ("lib", "mod"):
                rel = rel[:-1]
            files["::".join((cname,) + rel)] = f
    graph: Dict[str, Set[str]] = {m: set() for m in files}

    def module_of(path: List[str]) -> str:
        while path and "::".join(path) not in files:
            path = path[:-1]
        return "::".join(path)

    for mod, f in files.items():
        cname = mod.split("::")[0]
        is_dir = f.stem in ("lib", "mod")
        selfpath = mod.split("::")
        parent = selfpath if is_dir else selfpath[:-1]
        code = _strip_tests(_STRING.sub('""', _COMMENT.sub("", f.read_text(encoding="utf-8"))))
        # expand `use a::{b, c::d}` into `a::b`, `a::c::d`
        paths = []
        for m in _USE_GROUP.finditer(code):
            for item in re.split(r",(?![^{]*\})", m.group(3)):
                item = item.strip().split(" as ")[0].strip()
                if item and item != "self" and item != "*":
                    paths.append((m.group(1), m.group(2) + "::" + re.sub(r"\{.*", "", item).rstrip(":")))
                elif item == "self":
                    paths.append((m.group(1), m.group(2)))
        paths += [(m.group(1), m.group(2)) for m in _PATH.finditer(code)]
        for root, rest in paths:
            segs = [s for s in rest.split("::") if s]
            if root == "crate":
                base = [cname]
            elif root == "tubesweep_core":
                base = ["tubesweep_core"]
            elif root == "self":
                base = selfpath if is_dir else parent
            else:  # super
                base = parent[:-1] if not is_dir else selfpath[:-1]
                while segs and segs[0] == "super":
                    segs = segs[1:]
                    base = base[:-1]
            target = module_of(list(base) + segs)
            if target and target != mod and target.split("::")[0] in crates:
                graph[mod].add(target)
    # a folder's mod.rs re-exporting its children does not make the children depend on each
    # other: drop the edges child -> ancestor folder when the folder's file only re-exports
    for mod, f in files.items():
        if f.stem not in ("lib", "mod"):
            continue
        code = _strip_tests(_COMMENT.sub("", f.read_text(encoding="utf-8")))
        only_toc = not re.search(r"\b(fn|struct|enum|trait|impl|const|static|type)\b", code)
        if only_toc:
            for m in graph:
                if m.startswith(mod + "::"):
                    graph[m].discard(mod)
    return graph


def main() -> int:
    cycles = []
    for comp in strongly_connected(python_graph(ROOT / "python" / "tubesweep")):
        cycles.append("python: " + " <-> ".join(comp))
    crates = {
        "tubesweep_core": ROOT / "crates" / "tubesweep-core" / "src",
        "_native": ROOT / "crates" / "tubesweep-py" / "src",
    }
    for comp in strongly_connected(rust_graph(crates)):
        cycles.append("rust: " + " <-> ".join(comp))
    for c in cycles:
        print("import cycle:", c)
    if not cycles:
        print("import cycles: none (python/tubesweep, crates/*/src)")
    return 1 if cycles else 0


if __name__ == "__main__":
    sys.exit(main())
