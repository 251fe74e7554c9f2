#!/usr/bin/python3
"""Lists C++ function bodies longer than N lines (default 150): `scripts/long_functions.py [N] DIR...`.

A brace-counting reader (comments and literals stripped), not a parser: enough to find the functions
that need splitting; a long one that stays (a hot loop) says why in a comment."""
import re, sys, pathlib

def strip(text):
    # Removes comments, string and char literals (keeps newlines).
    out, i, n = [], 0, len(text)
    while i < n:
        c = text[i]
        if text.startswith('//', i):
            j = text.find('\n', i); j = n if j < 0 else j; i = j
        elif text.startswith('/*', i):
            j = text.find('*/', i + 2); j = n if j < 0 else j + 2
            out.append('\n' * text.count('\n', i, j)); i = j
        elif text.startswith('R"', i):
            m = re.match(r'R"([^(]*)\(', text[i:]); end = ')' + m.group(1) + '"'
            j = text.find(end, i); j = n if j < 0 else j + len(end)
            out.append('""' + '\n' * text.count('\n', i, j)); i = j
        elif c in '"\'':
            j = i + 1
            while j < n and text[j] != c:
                j += 2 if text[j] == '\\' else 1
            out.append('""'); i = j + 1
        else:
            out.append(c); i += 1
    return ''.join(out)

def functions(path):
    text = strip(path.read_text(errors='replace'))
    stack, results, last = [], [], 0   # stack of (kind, line, name)
    line = 1
    for i, c in enumerate(text):
        if c == '\n': line += 1
        elif c == '{':
            head = text[last:i]
            scope_ok = all(k == 'scope' for k, _, _ in stack)
            h = ' '.join(head.split())
            if re.search(r'\b(namespace|class|struct|union|enum)\b[^()]*$', h) or h.endswith('extern "C"') or not h:
                kind = 'scope' if scope_ok else 'block'
            elif scope_ok and re.search(r'\)\s*(const|noexcept|override|final|mutable|->[^{;]*|\s)*$', h) or (scope_ok and re.search(r'\)\s*:.*$', h)):
                m = re.search(r'([~\w:]+)\s*\([^;]*$', h)
                kind = 'func'; name = m.group(1) if m else '?'
                stack.append((kind, line, name)); last = i + 1; continue
            else:
                kind = 'block'
            stack.append((kind, line, ''))
            last = i + 1
        elif c == '}':
            if stack:
                kind, start, name = stack.pop()
                if kind == 'func': results.append((name, start, line, line - start + 1))
            last = i + 1
        elif c == ';':
            last = i + 1
    return results

limit = 150
args = sys.argv[1:]
if args and args[0].isdigit(): limit = int(args.pop(0))
for d in args or ['.']:
    for p in sorted(pathlib.Path(d).rglob('*')):
        if p.suffix in ('.cc', '.h', '.cpp') and 'build' not in p.parts:
            for name, a, b, n in functions(p):
                if n > limit: print(f'{p}:{a}-{b}: {name} ({n} lines)')
