#!/usr/bin/env python3
"""Finds seeded draws whose order C leaves unspecified: two calls of
functions that take a tu_rng * inside one full expression, whose nearest
common node evaluates its operands in no defined order (the arguments of
a call, the operands of an arithmetic or assignment operator, a subscript,
an initializer list). Reads clang's JSON AST. Usage: scripts/rng_order.py tests/test_*.c (exit 1 if any is found)."""
import json, subprocess, sys

UNSEQ_BIN_OK = {"&&", "||", ","}

def consumes(call):
    inner = call.get("inner") or []
    if not inner:
        return False
    t = json.dumps(inner[0].get("type", {}))
    return "tu_rng *" in t

def check(path, cflags):
    out = subprocess.run(["clang", "-fsyntax-only", "-Xclang", "-ast-dump=json"] + cflags + [path],
                         capture_output=True, text=True)
    if out.returncode != 0:
        sys.stderr.write(out.stderr)
        return -1
    root = json.loads(out.stdout)
    state = {"file": path, "line": 0}
    found = []

    def track(node):
        for key in ("loc", "range"):
            v = node.get(key)
            if not v:
                continue
            locs = [v] if key == "loc" else [v.get("begin", {})]
            for l in locs:
                l = l.get("expansionLoc", l)
                if "file" in l:
                    state["file"] = l["file"]
                if "line" in l:
                    state["line"] = l["line"]

    # walk: collect consuming calls with their ancestor paths
    def walk(node, path):
        track(node)
        if node.get("kind") == "CallExpr" and consumes(node):
            found.append((list(path), node, state["file"], state["line"]))
        for i, ch in enumerate(node.get("inner") or []):
            if isinstance(ch, dict):
                path.append((node, i))
                walk(ch, path)
                path.pop()
    walk(root, [])
    bad = set()
    for a in range(len(found)):
        for b in range(a + 1, len(found)):
            pa, na, fa, la = found[a]
            pb, nb, fb, lb = found[b]
            k = 0
            while k < len(pa) and k < len(pb) and pa[k][0] is pb[k][0] and pa[k][1] == pb[k][1]:
                k += 1
            if k >= len(pa) or k >= len(pb):
                continue   # one inside the other: argument before the call
            if pa[k][0] is not pb[k][0]:
                continue
            lca = pa[k][0]
            kind = lca.get("kind")
            why = None
            if kind == "CallExpr":
                why = "arguments of one call"
            elif kind in ("BinaryOperator", "CompoundAssignOperator"):
                if lca.get("opcode") not in UNSEQ_BIN_OK:
                    why = "operands of '%s'" % lca.get("opcode")
            elif kind == "InitListExpr":
                why = "one initializer list"
            elif kind == "ArraySubscriptExpr":
                why = "array and index"
            if why:
                bad.add((fa, la, why))
    for f, l, why in sorted(bad):
        print("%s:%d: seeded draws in one full expression (%s): order unspecified" % (f, l, why))
    return len(bad)

if __name__ == "__main__":
    flags = ["-std=c11", "-D_GNU_SOURCE", "-Isrc", "-Itests"]
    # the io tests' headers (SDL2, libdrm, libusb): where pkg-config has them
    pc = subprocess.run(["pkg-config", "--cflags", "sdl2", "libdrm", "libusb-1.0", "libpng"],
                        capture_output=True, text=True)
    if pc.returncode == 0:
        flags += pc.stdout.split()
    total = 0
    for p in sys.argv[1:]:
        n = check(p, flags)
        if n < 0:
            sys.exit(2)
        total += n
    sys.exit(1 if total else 0)
