#!/usr/bin/env python3
"""Third-party licences of what trisort ships: render THIRD-PARTY-NOTICES.md, or check it.

  licences.py render --about-json FILE [-o THIRD-PARTY-NOTICES.md]
      Writes the notices from cargo-about's JSON (licence texts; scripts/third-party-notices.sh
      runs cargo-about) and from the shipped crate set computed here.
  licences.py check [--notices FILE] [--allow-list FILE]
      CI's check (scripts/check-licences.sh), standard library only, no cargo-about: recomputes
      the shipped crates and their licence expressions from Cargo.lock with `cargo tree`, fails
      if a licence is not on the allow-list (about.toml) or if the notices miss a crate, list a
      stale version or licence, or list a crate no longer shipped.

What ships: every workspace member with a `bin`, `cdylib` or `staticlib` target (the CLI, the
C libraries, the web player), each for the targets it is built for (NATIVE_TARGETS, or
WASM_TARGETS for WASM_ROOTS). Its crates are the non-dev, non-build-script dependencies that
Cargo resolves for that package alone (`cargo tree -e normal -p ROOT --target ...`).
Procedural macros and what only they use run at build time and are not linked; they are listed
apart, since the code they generate is.
"""

from __future__ import annotations

import argparse
import hashlib
import json
import re
import subprocess
import sys
from dataclasses import dataclass, field
from pathlib import Path

try:
    import tomllib
except ImportError:  # Python < 3.11
    sys.exit("licences: needs Python 3.11 or later (tomllib)")

ROOT = Path(__file__).resolve().parent.parent
NOTICES = ROOT / "THIRD-PARTY-NOTICES.md"
ALLOW_LIST = ROOT / "about.toml"
GENERATOR = "scripts/third-party-notices.sh"

NATIVE_TARGETS = ["x86_64-unknown-linux-gnu", "aarch64-unknown-linux-gnu"]
WASM_TARGETS = ["wasm32-unknown-unknown"]
# Shipped packages built for the browser only (natively they are a small test-only crate).
WASM_ROOTS = {"trisort-web"}
SHIPPED_KINDS = {"bin", "cdylib", "staticlib"}

# Bundled non-Rust code, said in the notices next to the crate when it ships.
BUNDLED_CODE = {
    "zstd-sys": "compiles the Zstandard C library it vendors (`zstd/`, Copyright Meta Platforms, "
    "Inc.). Zstandard is offered under BSD-3-Clause or GPL-2.0-only; trisort takes it under "
    "BSD-3-Clause, and the crate declares only that. Its texts below are the crate's, the "
    "generated bindings' and Zstandard's own.",
    "meshopt": "compiles the meshoptimizer C++ library it vendors (`vendor/src`, MIT, Copyright "
    "Arseny Kapoulkine). The crate ships no licence file, so meshoptimizer's notice is taken "
    "from `meshoptimizer.h` (about.toml clarifies the crate as `(MIT OR Apache-2.0) AND MIT`).",
    "nv-flip-sys": "compiles NVIDIA's FLIP C++ (BSD-3-Clause) and the single-header libraries "
    "FLIP includes: tinyexr (BSD-3-Clause, with OpenEXR code under BSD-3-Clause, Copyright "
    "Industrial Light & Magic), the miniz 1.15 inside tinyexr (public domain, Unlicense) and "
    "stb_image / stb_image_write (MIT OR Unlicense, taken as MIT). The crate ships no licence "
    "files, so the texts are taken from those headers (about.toml clarifies the crate).",
    "blake3": "compiles its own C and assembly implementations, under the crate's licence.",
}


def fail(message: str) -> None:
    print(f"licences: {message}", file=sys.stderr)
    sys.exit(1)


def cargo(*args: str) -> str:
    proc = subprocess.run(["cargo", *args], cwd=ROOT, capture_output=True, text=True)
    if proc.returncode != 0:
        sys.stderr.write(proc.stderr)
        fail(f"`cargo {' '.join(args)}` failed (exit {proc.returncode})")
    return proc.stdout


# --- What ships ----------------------------------------------------------------------------


@dataclass
class Root:
    name: str
    targets: list[str]
    artefacts: list[str]  # e.g. "bin trisort", "lib trisort_capi (cdylib, staticlib)"


@dataclass
class Crate:
    name: str
    version: str
    license: str  # as declared in its Cargo.toml ("" when it declares only a licence file)
    linked_by: set[str] = field(default_factory=set)
    build_time_by: set[str] = field(default_factory=set)

    @property
    def key(self) -> tuple[str, str]:
        return (self.name, self.version)


def shipped_roots() -> tuple[list[Root], set[str]]:
    meta = json.loads(cargo("metadata", "--locked", "--no-deps", "--format-version", "1"))
    members = set(meta["workspace_members"])
    roots, names = [], set()
    for pkg in meta["packages"]:
        if pkg["id"] not in members:
            continue
        names.add(pkg["name"])
        artefacts = []
        for t in pkg["targets"]:
            kinds = [k for k in t["kind"] if k in SHIPPED_KINDS]
            if kinds == ["bin"]:
                artefacts.append(f"bin `{t['name']}`")
            elif kinds:
                artefacts.append(f"lib `{t['name']}` ({', '.join(kinds)})")
        if artefacts:
            targets = WASM_TARGETS if pkg["name"] in WASM_ROOTS else NATIVE_TARGETS
            roots.append(Root(pkg["name"], targets, artefacts))
    missing = WASM_ROOTS - names
    if missing:
        fail(f"WASM_ROOTS names {sorted(missing)}, not a workspace member: "
             "update scripts/licences.py")
    return sorted(roots, key=lambda r: r.name), names


LINE = re.compile(r"^(\d+)(\S+) v(\S+)(.*?)\|(.*?)( \(\*\))?$")


def shipped_crates(roots: list[Root], workspace: set[str]) -> dict[tuple[str, str], Crate]:
    """Third-party crates per root, from `cargo tree` (Cargo's own resolver and Cargo.lock)."""
    crates: dict[tuple[str, str], Crate] = {}
    for root in roots:
        args = ["tree", "--locked", "-e", "normal", "--prefix", "depth", "-f", "{p}|{l}"]
        for t in root.targets:
            args += ["--target", t]
        out = cargo(*args, "-p", root.name)
        children: dict[tuple[str, str], set[tuple[str, str]]] = {}
        proc_macro: set[tuple[str, str]] = set()
        stack: list[tuple[str, str]] = []
        top = None
        for line in out.splitlines():
            if not line.strip():
                continue
            m = LINE.match(line)
            if not m:
                fail(f"cannot read `cargo tree` line {line!r}")
            depth, name, version, extra, lic = int(m[1]), m[2], m[3], m[4], m[5]
            node = (name, version)
            if "(proc-macro)" in extra:
                proc_macro.add(node)
            if name not in workspace and node not in crates:
                crates[node] = Crate(name, version, lic.strip())
            del stack[depth:]
            if depth == 0 and top is None:
                top = node
            if depth:
                children.setdefault(stack[-1], set()).add(node)
            stack.append(node)
        if top is None or top[0] != root.name:
            fail(f"`cargo tree -p {root.name}` printed no tree of {root.name}")
        # Linked: reachable without passing through a procedural macro.
        linked, seen = set(), set()
        todo = [top]
        while todo:
            n = todo.pop()
            if n in linked:
                continue
            linked.add(n)
            todo += [c for c in children.get(n, ()) if c not in proc_macro]
        todo = [top]
        while todo:
            n = todo.pop()
            if n in seen:
                continue
            seen.add(n)
            todo += list(children.get(n, ()))
        for n in seen:
            if n in crates:
                (crates[n].linked_by if n in linked else crates[n].build_time_by).add(root.name)
    return crates


# --- The allow-list ------------------------------------------------------------------------


def load_allow_list(path: Path) -> tuple[list[str], dict[str, list[str]], dict[str, str]]:
    """(accepted, extra accepted per crate, clarified expression per crate) from about.toml."""
    with open(path, "rb") as f:
        cfg = tomllib.load(f)
    accepted = cfg.get("accepted")
    if not isinstance(accepted, list) or not accepted:
        fail(f"{path.name} has no `accepted` list")
    per_crate, clarified = {}, {}
    for key, value in cfg.items():
        if isinstance(value, dict) and key != "private":
            per_crate[key] = list(value.get("accepted", []))
            if "clarify" in value:
                clarified[key] = value["clarify"]["license"]
    return accepted, per_crate, clarified


def parse_spdx(expr: str):
    """SPDX expression -> ("or"|"and", [..]) or ("id", "X" / "X WITH E"). "/" reads as OR."""
    tokens = re.findall(r"\(|\)|[^\s()/]+|/", expr)
    pos = 0

    def peek():
        return tokens[pos] if pos < len(tokens) else None

    def take():
        nonlocal pos
        pos += 1
        return tokens[pos - 1]

    def or_expr():
        terms = [and_expr()]
        while peek() is not None and (peek().upper() == "OR" or peek() == "/"):
            take()
            terms.append(and_expr())
        return terms[0] if len(terms) == 1 else ("or", terms)

    def and_expr():
        terms = [with_expr()]
        while peek() is not None and peek().upper() == "AND":
            take()
            terms.append(with_expr())
        return terms[0] if len(terms) == 1 else ("and", terms)

    def with_expr():
        tok = take() if peek() is not None else None
        if tok == "(":
            node = or_expr()
            if take() != ")":
                raise ValueError
            return node
        if tok is None or tok in (")", "/") or tok.upper() in ("AND", "OR", "WITH"):
            raise ValueError
        if peek() is not None and peek().upper() == "WITH":
            take()
            return ("id", f"{tok} WITH {take()}")
        return ("id", tok)

    try:
        node = or_expr()
        if pos != len(tokens):
            raise ValueError
        return node
    except (ValueError, IndexError):
        raise ValueError(f"cannot parse licence expression {expr!r}") from None


def satisfied(node, allowed: set[str]) -> bool:
    kind, val = node
    if kind == "id":
        return val in allowed
    results = [satisfied(n, allowed) for n in val]
    return any(results) if kind == "or" else all(results)


def effective_license(crate: Crate, clarified: dict[str, str]) -> str:
    return clarified.get(crate.name, crate.license)


# --- The notices file ----------------------------------------------------------------------

ROW = re.compile(r"^\| `([^`]+)` \| `([^`]+)` \| `([^`]*)` \| ([^|]*) \| ([^|]*) \| ([^|]*) \|$")


def roots_cell(crate: Crate) -> str:
    return ", ".join(sorted(crate.linked_by or crate.build_time_by))


def read_notices(path: Path) -> dict[tuple[str, str], dict]:
    rows, section = {}, None
    anchors = set(re.findall(r'<a id="([^"]+)"></a>', path.read_text(encoding="utf-8")))
    for line in path.read_text(encoding="utf-8").splitlines():
        if line.startswith("## "):
            section = "linked" if line.startswith("## Linked") else (
                "build" if line.startswith("## Build time") else None)
        m = ROW.match(line)
        if m and section:
            texts = re.findall(r"\(#([^)]+)\)", m[6])
            rows[(m[1], m[2])] = {"section": section, "license": m[3], "roots": m[5].strip(),
                                  "texts": texts,
                                  "dangling": [t for t in texts if t not in anchors]}
    return rows


def check(args) -> None:
    accepted, per_crate, clarified = load_allow_list(args.allow_list)
    roots, workspace = shipped_roots()
    crates = shipped_crates(roots, workspace)
    errors = []
    for c in sorted(crates.values(), key=lambda c: c.key):
        where = roots_cell(c) + ("" if c.linked_by else " (build time)")
        expr = effective_license(c, clarified)
        if not expr:
            errors.append(f"{c.name} {c.version} ({where}) declares no SPDX licence expression: "
                          f"read its licence and add a [{c.name}.clarify] to "
                          f"{args.allow_list.name}")
            continue
        allowed = set(accepted) | set(per_crate.get(c.name, []))
        # A clarification replaces the declared expression in the notices; both must pass (a
        # crate that changes its licence keeps its clarification until someone reads it again).
        for e in dict.fromkeys(x for x in (expr, c.license) if x):
            try:
                ok = satisfied(parse_spdx(e), allowed)
            except ValueError as err:
                errors.append(f"{c.name} {c.version}: {err}")
                continue
            if not ok:
                errors.append(f"{c.name} {c.version} ({where}) is licensed `{e}`, which the "
                              f"allow-list in {args.allow_list.name} does not accept")
    if not args.notices.exists():
        errors.append(f"{args.notices.name} is missing: run {GENERATOR}")
        listed = {}
    else:
        listed = read_notices(args.notices)
        if not listed:
            errors.append(f"{args.notices.name} lists no crates: run {GENERATOR}")
    stale = f"run {GENERATOR}"
    shipped_names = {c.name for c in crates.values()}
    reported = set()
    for c in sorted(crates.values(), key=lambda c: c.key):
        if not args.notices.exists():
            break
        row = listed.get(c.key)
        if row is None:
            others = [v for (n, v) in listed if n == c.name and (n, v) not in crates]
            if others:
                reported.update((c.name, v) for v in others)
                errors.append(f"{args.notices.name} lists {c.name} {', '.join(others)} but "
                              f"Cargo.lock has {c.name} {c.version} ({roots_cell(c)}): "
                              f"stale, {stale}")
            else:
                errors.append(f"{c.name} {c.version} ships ({roots_cell(c)}) but is not in "
                              f"{args.notices.name}: {stale}")
            continue
        expr = effective_license(c, clarified)
        if row["license"] != expr:
            errors.append(f"{args.notices.name} gives {c.name} {c.version} the licence "
                          f"`{row['license']}`; the locked crate's is `{expr}`: {stale}")
        want = "linked" if c.linked_by else "build"
        if row["section"] != want or row["roots"] != roots_cell(c):
            said = "linked into" if row["section"] == "linked" else "used at build time by"
            truth = "linked into" if c.linked_by else "used at build time by"
            errors.append(f"{args.notices.name} says {c.name} {c.version} is {said} "
                          f"{row['roots']}; it is {truth} {roots_cell(c)}: {stale}")
        if not row["texts"] or row["dangling"]:
            errors.append(f"{args.notices.name}: {c.name} {c.version} has no licence text "
                          f"(or links a missing one): {stale}")
    for name, version in sorted(set(listed) - set(crates) - reported):
        if name in shipped_names:
            errors.append(f"{args.notices.name} lists {name} {version}, not a version Cargo.lock "
                          f"ships: stale, {stale}")
        else:
            errors.append(f"{args.notices.name} lists {name} {version}, which no shipped "
                          f"artefact uses any more: {stale}")
    linked = sum(1 for c in crates.values() if c.linked_by)
    if errors:
        for e in errors:
            print(f"licences: {e}", file=sys.stderr)
        fail(f"{len(errors)} problem(s) in {len(crates)} third-party crates")
    print(f"licences: ok: {len(crates)} third-party crates ({linked} linked, "
          f"{len(crates) - linked} build time only) of {', '.join(r.name for r in roots)}: "
          f"licences on the allow-list, {args.notices.name} up to date")


# --- Rendering -----------------------------------------------------------------------------


def fence_for(text: str) -> str:
    longest = max((len(m) for m in re.findall(r"`+", text)), default=0)
    return "`" * max(3, longest + 1)


def source_label(lic: dict) -> str | None:
    """Where cargo-about found a text, as `crate-version/path` (None: the standard text)."""
    path = lic.get("source_path")
    if path is None:
        return None
    m = re.search(r"/registry/src/[^/]+/(.+)$", path)
    if m:
        return m[1]
    if Path(path).is_absolute():
        return Path(path).name
    first = lic["used_by"][0]["crate"] if lic["used_by"] else None
    return f"{first['name']}-{first['version']}/{path}" if first else path


def render(args) -> None:
    accepted, per_crate, clarified = load_allow_list(ALLOW_LIST)
    about = json.loads(Path(args.about_json).read_text(encoding="utf-8"))
    roots, workspace = shipped_roots()
    crates = shipped_crates(roots, workspace)

    # Licence texts per crate, from cargo-about (deduplicated by text).
    texts: dict[str, dict] = {}
    crate_texts: dict[tuple[str, str], list[str]] = {}
    for lic in about["licenses"]:
        body = "\n".join(line.rstrip() for line in lic["text"].splitlines()).strip("\n")
        digest = hashlib.sha256(body.encode()).hexdigest()[:10]
        anchor = f"{lic['id'].lower().replace(' ', '-')}-{digest}"
        entry = texts.setdefault(anchor, {"id": lic["id"], "name": lic["name"], "text": body,
                                          "source": source_label(lic),
                                          "used_by": set()})
        for u in lic["used_by"]:
            key = (u["crate"]["name"], u["crate"]["version"])
            if key in crates:
                entry["used_by"].add(key)
                crate_texts.setdefault(key, [])
                if anchor not in crate_texts[key]:
                    crate_texts[key].append(anchor)
    # Apache-2.0 § 4(d): a NOTICE file travels with the work.
    crate_dirs = {(c["package"]["name"], c["package"]["version"]):
                  Path(c["package"]["manifest_path"]).parent for c in about["crates"]}
    notice_files = {}
    for key in sorted(crates):
        if "Apache-2.0" in {texts[a]["id"] for a in crate_texts.get(key, [])} and key in crate_dirs:
            d = crate_dirs[key]
            found = sorted(p for p in list(d.glob("*")) + list(d.glob("*/*"))
                           if p.is_file() and p.name.upper().startswith("NOTICE"))
            if found:
                notice_files[key] = [(p.relative_to(d), p.read_text(encoding="utf-8",
                                      errors="replace").replace("\r\n", "\n").strip("\n"))
                                     for p in found]
    # cargo-about only warns when a clarification's checksum no longer matches (a new crate
    # version) and falls back to what it detects: fail instead, so that the vendored code's
    # notices cannot silently drop out.
    with open(ALLOW_LIST, "rb") as f:
        cfg = tomllib.load(f)
    for key in sorted(crates):
        clar = cfg.get(key[0], {}).get("clarify") if isinstance(cfg.get(key[0]), dict) else None
        for cf in (clar or {}).get("files", []):
            path = crate_dirs[key] / cf["path"]
            text = ""
            if path.exists():
                with open(path, encoding="utf-8", newline="") as f:  # keep CR LF: cargo-about does
                    text = f.read()
            start = text.find(cf["start"]) if "start" in cf else 0
            end = text.find(cf["end"], max(start, 0)) if "end" in cf else len(text)
            excerpt = text[start:end + len(cf.get("end", ""))] if start >= 0 <= end else ""
            if hashlib.sha256(excerpt.encode()).hexdigest() != cf["checksum"]:
                fail(f"about.toml clarifies {key[0]} with {cf['path']}, which no longer matches "
                     f"its checksum in {key[0]} {key[1]}: read the crate's licences again and "
                     "update the clarification")
    about_licenses = {(c["package"]["name"], c["package"]["version"]): c["license"]
                      for c in about["crates"]}
    problems = [f"{n} {v}" for (n, v) in sorted(crates) if (n, v) not in crate_texts]
    if problems:
        fail(f"cargo-about gave no licence text for {', '.join(problems)}")
    def same(x: str, y: str) -> bool:
        try:
            return parse_spdx(x) == parse_spdx(y)
        except ValueError:
            return x == y

    for key, c in sorted(crates.items()):
        if key in about_licenses and not same(about_licenses[key], effective_license(c, clarified)):
            print(f"licences: note: cargo-about reads {c.name} {c.version} as "
                  f"`{about_licenses[key]}`, Cargo.toml says `{c.license}`", file=sys.stderr)

    out = []
    w = out.append
    w("# Third-party notices")
    w("")
    w(f"<!-- Generated by {GENERATOR} (cargo-about and scripts/licences.py) from Cargo.lock and "
      "about.toml. Do not edit by hand; CI (scripts/check-licences.sh) checks it is current. -->")
    w("")
    w("trisort itself is licensed under MIT OR Apache-2.0 (LICENSE-MIT, LICENSE-APACHE). "
      "The artefacts it ships contain the third-party Rust crates below. For each crate: its "
      "version (from Cargo.lock), its licence expression as its Cargo.toml declares it (or as "
      "about.toml clarifies it where the crate bundles code under other terms), the licence(s) "
      "trisort takes it under where it offers a choice (the first in about.toml's list), the "
      "artefacts it is in, and links to the licence texts at the end of this file.")
    w("")
    w("Artefacts (Cargo package: targets; built for):")
    w("")
    for r in roots:
        w(f"- `{r.name}`: {', '.join(r.artefacts)}; {', '.join(f'`{t}`' for t in r.targets)}")
    w("")
    w("Scope. The crate set is what Cargo resolves for each package alone, for the targets above, "
      "without dev-dependencies and build scripts' dependencies (`cargo tree -e normal`). Not "
      "listed: the Rust standard library, which every artefact links statically (MIT OR "
      "Apache-2.0, https://github.com/rust-lang/rust/blob/master/COPYRIGHT); system libraries "
      "the artefacts link or load at run time but trisort does not distribute (the C library, "
      "libstdc++ and libgcc where crates below compile C++, Vulkan, EGL/GL, X11 and Wayland "
      "client libraries); and the JavaScript glue wasm-bindgen generates for the web player "
      "(from the `wasm-bindgen` crate, listed).")
    w("")
    w("Licence texts are the files the crates ship, found by cargo-about, including those of C "
      "and C++ code vendored in a crate's sub-directories. Where a crate ships no file for a "
      "licence, the standard (SPDX) text is given, marked as such: it names no copyright holder.")
    w("")
    bundled = [(n, note) for n, note in BUNDLED_CODE.items() if any(k[0] == n for k in crates)]
    if bundled:
        w("Bundled C, C++ and assembly code:")
        w("")
        for n, note in bundled:
            versions = ", ".join(v for (cn, v) in sorted(crates) if cn == n)
            w(f"- `{n}` {versions} {note}")
        w("")

    def table(rows):
        w("| Crate | Version | Licence | Used under | In | Texts |")
        w("|---|---|---|---|---|---|")
        for c in rows:
            anchors = crate_texts[c.key]
            used = " AND ".join(sorted({texts[a]["id"] for a in anchors}))
            links = ", ".join(f"[{texts[a]['id']}](#{a})" for a in anchors)
            w(f"| `{c.name}` | `{c.version}` | `{effective_license(c, clarified)}` | {used} | "
              f"{roots_cell(c)} | {links} |")
        w("")

    ordered = sorted(crates.values(), key=lambda c: (c.name, c.version))
    linked = [c for c in ordered if c.linked_by]
    build = [c for c in ordered if not c.linked_by]
    w(f"## Linked into the artefacts ({len(linked)} crates)")
    w("")
    table(linked)
    w(f"## Build time only ({len(build)} crates)")
    w("")
    w("Procedural macros and the crates only they use run inside the compiler and are not "
      "linked; the code they generate is, so they are listed too.")
    w("")
    table(build)
    w("## NOTICE files")
    w("")
    if not notice_files:
        w("None of the crates used under Apache-2.0 ships a NOTICE file (Apache-2.0 § 4(d)).")
        w("")
    for (n, v), files in sorted(notice_files.items()):
        for rel, body in files:
            w(f"### {n} {v}: `{rel}`")
            w("")
            fence = fence_for(body)
            w(f"{fence}text")
            w(body)
            w(fence)
            w("")
    w("## Licence texts")
    w("")
    order = sorted((a for a in texts if texts[a]["used_by"]),
                   key=lambda a: (texts[a]["id"], texts[a]["source"] is None, a))
    for a in order:
        t = texts[a]
        w(f'### <a id="{a}"></a>{t["name"]} ({t["id"]})'
          + ("" if t["source"] else " — standard text, no copyright line"))
        w("")
        w("Used by: " + ", ".join(f"{n} {v}" for n, v in sorted(t["used_by"])))
        w("")
        w(f"From `{t['source']}`." if t["source"] else
          "The standard text from the SPDX licence list, naming no copyright holder: these "
          "crates ship this exact text, or no licence file at all.")
        w("")
        fence = fence_for(t["text"])
        w(f"{fence}text")
        w(t["text"])
        w(fence)
        w("")
    Path(args.output).write_text("\n".join(out).rstrip("\n") + "\n", encoding="utf-8")
    print(f"licences: wrote {args.output}: {len(linked)} linked and {len(build)} build-time "
          f"crates, {len(order)} licence texts")


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__,
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = p.add_subparsers(dest="cmd", required=True)
    r = sub.add_parser("render", help="write the notices from cargo-about's JSON")
    r.add_argument("--about-json", required=True)
    r.add_argument("-o", "--output", default=str(NOTICES))
    c = sub.add_parser("check", help="check licences and the notices against Cargo.lock")
    c.add_argument("--notices", type=Path, default=NOTICES)
    c.add_argument("--allow-list", type=Path, default=ALLOW_LIST)
    args = p.parse_args()
    (render if args.cmd == "render" else check)(args)


if __name__ == "__main__":
    main()
