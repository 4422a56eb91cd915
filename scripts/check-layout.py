#!/usr/bin/env python3
"""Layout rules of the workspace (issue 26), checked in CI:

1. no function longer than 100 lines in any Rust file of the workspace (every crate's `src`,
   `examples`, `tests` and `benches`, the top-level `tests`, `python/src`);
2. no circle of files inside any crate: nodes are sibling modules (files or folders under one
   parent), edges are `crate::...` / `super::...` references from code in one sibling into
   another; every strongly connected component with more than one node is a circle.

`--self-test` runs both checks on a synthetic crate with one violation of each (negative
control) and on a clean one. Exit code 1 on any violation.
"""
import os, re, sys, tempfile

MAX_LINES = 100
KINDS = ["src", "examples", "tests", "benches"]
FN_RE = re.compile(r'^\s*(pub(\([^)]*\))?\s+)?(const\s+)?(async\s+)?(unsafe\s+)?fn\s+(\w+)')
REF_RE = re.compile(r'\b(crate|super)((?:::\w+)+)')
GROUP_RE = re.compile(r'\buse\s+(crate|super)((?:::\w+)*)::\{([^;]*)\}', re.S)


def rs_files(root):
    for dp, _, fs in os.walk(root):
        for f in sorted(fs):
            if f.endswith('.rs'):
                yield os.path.join(dp, f)


def strip_line(s):
    s = re.sub(r'//.*', '', s)
    s = re.sub(r'"(\\.|[^"\\])*"', '""', s)
    return re.sub(r"'(\\.|[^'\\])'", "''", s)


def long_functions(root, limit=MAX_LINES):
    out = []
    for p in rs_files(root):
        lines = open(p, encoding='utf-8', errors='replace').read().split('\n')
        for i, line in enumerate(lines):
            m = FN_RE.match(line)
            if not m:
                continue
            depth, started, j = 0, False, i
            while j < len(lines):
                s = strip_line(lines[j])
                if ';' in s and not started and '{' not in s:
                    break
                depth += s.count('{') - s.count('}')
                started = started or '{' in s
                if started and depth <= 0:
                    break
                j += 1
            if started and j - i + 1 > limit:
                out.append(f"{p}:{i + 1} fn {m.group(6)} has {j - i + 1} lines (limit {limit})")
    return out


def modpath(src, p):
    rel = os.path.relpath(p, src)[:-3].split(os.sep)
    return rel[:-1] if rel[-1] in ("mod", "lib", "main") else rel


def circles(src):
    files = list(rs_files(src))
    mods = {tuple(modpath(src, p)) for p in files}
    edges = set()
    for p in files:
        me = modpath(src, p)
        is_dir = os.path.basename(p) in ("mod.rs", "lib.rs", "main.rs")
        text = re.sub(r'//[^\n]*', '', open(p, encoding='utf-8', errors='replace').read())
        text = re.split(r'#\[cfg\(test\)\]\s*mod tests', text)[0]
        targets = [(m.group(1), m.group(2).split('::')[1:]) for m in REF_RE.finditer(text)]
        for m in GROUP_RE.finditer(text):
            base = m.group(2).split('::')[1:] if m.group(2) else []
            for item in m.group(3).split(','):
                item = item.strip().split(' as ')[0].strip()
                if item and not item.startswith('{'):
                    targets.append((m.group(1), base + [s for s in item.split('::') if s and s != 'self']))
        for kind, segs in targets:
            tgt = segs if kind == 'crate' else (me if is_dir else me[:-1])[:-1] + segs
            best = next((tgt[:k] for k in range(len(tgt), -1, -1) if tuple(tgt[:k]) in mods), None)
            if best is None:
                continue
            c = 0
            while c < min(len(me), len(best)) and me[c] == best[c]:
                c += 1
            if c < len(me) and c < len(best):  # siblings below a common parent
                edges.add(('/'.join(me[:c + 1]), '/'.join(best[:c + 1])))
    graph = {}
    for u, v in edges:
        graph.setdefault(u, set()).add(v)
        graph.setdefault(v, set())
    index, low, stack, on, found, counter = {}, {}, [], set(), [], [0]

    def visit(v):
        index[v] = low[v] = counter[0]
        counter[0] += 1
        stack.append(v)
        on.add(v)
        for w in sorted(graph[v]):
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
                found.append(sorted(comp))

    sys.setrecursionlimit(10000)
    for v in sorted(graph):
        if v not in index:
            visit(v)
    return [f"{src}: circle of files {c}" for c in found]


def check(repo):
    problems = []
    crate_dirs = [os.path.join(repo, 'crates', c, k) for c in sorted(os.listdir(os.path.join(repo, 'crates'))) for k in KINDS]
    for d in crate_dirs + [os.path.join(repo, 'tests'), os.path.join(repo, 'python', 'src')]:
        if os.path.isdir(d):
            problems += long_functions(d)
    crates = [os.path.join(repo, 'crates', c, 'src') for c in sorted(os.listdir(os.path.join(repo, 'crates')))]
    for src in crates + [os.path.join(repo, 'python', 'src')]:
        if os.path.isdir(src):
            problems += circles(src)
    return problems


def self_test():
    with tempfile.TemporaryDirectory() as d:
        src = os.path.join(d, 'src')
        os.makedirs(src)
        open(os.path.join(src, 'lib.rs'), 'w').write('mod a;\nmod b;\n')
        open(os.path.join(src, 'a.rs'), 'w').write('use crate::b::B;\npub struct A;\n')
        open(os.path.join(src, 'b.rs'), 'w').write(
            'pub struct B;\npub fn long() {\n' + '    let _x = crate::a::A;\n' * (MAX_LINES - 1) + '}\n')
        bad_circle, bad_long = circles(src), long_functions(src)
        assert len(bad_circle) == 1 and 'a' in bad_circle[0] and 'b' in bad_circle[0], bad_circle
        assert len(bad_long) == 1 and 'fn long' in bad_long[0], bad_long
        # one line fewer: exactly the limit, allowed
        open(os.path.join(src, 'b.rs'), 'w').write('pub struct B;\npub fn short() {\n' + '    let _x = 1;\n' * (MAX_LINES - 2) + '}\n')
        assert circles(src) == [] and long_functions(src) == [], (circles(src), long_functions(src))
    print(f"check-layout self-test: a circle and a function of {MAX_LINES + 1} lines are caught; the clean crate, with a function of {MAX_LINES}, passes")


if __name__ == '__main__':
    if '--self-test' in sys.argv:
        self_test()
        sys.exit(0)
    repo = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    problems = check(repo)
    for p in problems:
        print(p)
    print(f"check-layout: {len(problems)} problem(s)")
    sys.exit(1 if problems else 0)
