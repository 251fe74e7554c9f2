#!/usr/bin/python3
"""The README's dependency graph, read from CMake rather than drawn by hand.

  scripts/layout_graph.py                 prints the graph of the libraries' links
  scripts/layout_graph.py --update FILE   writes it between FILE's layout-graph markers
  scripts/layout_graph.py --check FILE    exits 1 when FILE's block differs from CMake's links, or
                                          when a library reaches one the layering forbids (MUST_NOT_REACH)

Each folder's CMakeLists.txt declares `add_library(ibrdf_NAME ...)` and its `target_link_libraries`;
every ibrdf_* library named there (PUBLIC or PRIVATE, ibrdf_warnings aside) is an edge. apps/ is drawn
from its `ibrdf_add_command(...)` lines: each subcommand's binary and the libraries it links.
"""
import pathlib
import re
import sys

ROOT = pathlib.Path(__file__).resolve().parent.parent
BEGIN, END = '<!-- layout-graph -->', '<!-- /layout-graph -->'
NOT_LIBRARY_FOLDERS = {'tests', 'fuzz', 'benchmarks', 'apps', 'build', 'python'}
# The layering the code relies on, checked on the transitive links: derender consumes a calibrated
# session (it neither fits nor calibrates), radiometry is the one radiometric chain above core, and
# reconstruct reads sample files (it needs nothing of the stages that make them).
MUST_NOT_REACH = {
    'derender': ['align', 'calibrate'],
    'radiometry': ['align', 'calibrate', 'derender', 'scan', 'reconstruct', 'report', 'synth', 'workflow'],
    'reconstruct': ['derender', 'align', 'calibrate', 'scan', 'synth', 'radiometry'],
    'workflow': ['derender', 'align', 'calibrate', 'scan', 'reconstruct', 'report', 'synth'],
    'core': ['radiometry', 'align', 'calibrate', 'derender', 'scan', 'reconstruct', 'report', 'synth'],
}


def strip_comments(text):
    return '\n'.join(line.split('#', 1)[0] for line in text.splitlines())


def library_links():
    """{library: sorted direct ibrdf_* links} for every library folder."""
    links = {}
    for cmake in sorted(ROOT.glob('*/CMakeLists.txt')):
        if cmake.parent.name in NOT_LIBRARY_FOLDERS:
            continue
        text = strip_comments(cmake.read_text())
        for name in re.findall(r'add_library\(\s*ibrdf_(\w+)\b(?!\s+(?:MODULE|OBJECT|INTERFACE))', text):
            deps = set()
            for body in re.findall(r'target_link_libraries\(\s*ibrdf_%s\b([^)]*)\)' % name, text):
                deps |= set(re.findall(r'\bibrdf_(\w+)', body))
            deps.discard('warnings')
            deps.discard(name)
            links[name] = sorted(deps)
    return links


def command_links():
    """{subcommand: sorted ibrdf_* libraries} from apps/CMakeLists.txt."""
    text = strip_comments((ROOT / 'apps' / 'CMakeLists.txt').read_text())
    commands = {}
    for name, rest in re.findall(r'^\s*ibrdf_add_command\((\w+)\s+\d+\s+"[^"]*"([^)]*)\)', text, re.M):
        commands[name] = sorted(set(re.findall(r'\bibrdf_(\w+)', rest)))
    return commands


def reach(name, links):
    seen, todo = set(), list(links.get(name, []))
    while todo:
        d = todo.pop()
        if d not in seen:
            seen.add(d)
            todo.extend(links.get(d, []))
    return seen


def layering_errors():
    links = library_links()
    errors = []
    for name, forbidden in MUST_NOT_REACH.items():
        if name in links:
            bad = sorted(reach(name, links) & set(forbidden))
            if bad:
                errors.append('ibrdf_%s links %s (directly or through its links); the layering forbids it'
                              % (name, ', '.join('ibrdf_' + b for b in bad)))
    return errors


def depth(name, links, memo):
    if name not in memo:
        memo[name] = 1 + max((depth(d, links, memo) for d in links.get(name, []) if d in links), default=-1)
    return memo[name]


def graph():
    links = library_links()
    memo = {}
    order = sorted(links, key=lambda n: (-depth(n, links, memo), n))
    width = max(len(n) for n in order)
    lines = ['```', 'library%s  links (direct, from its CMakeLists.txt)' % (' ' * (width - 7))]
    for name in order:
        lines.append('%s  ──> %s' % (name.ljust(width), ', '.join(links[name]) or '(third-party only)'))
    lines.append('')
    lines.append('apps: ibrdf-<subcommand>  ──> its libraries (apps/CMakeLists.txt)')
    commands = command_links()
    cwidth = max(len(c) for c in commands)
    for name in sorted(commands):
        lines.append('  %s  ──> %s' % (name.ljust(cwidth), ', '.join(commands[name])))
    lines.append('```')
    return '\n'.join(lines)


def replace_block(text, block):
    if BEGIN not in text or END not in text:
        raise SystemExit('layout_graph.py: the file has no %s ... %s block' % (BEGIN, END))
    head, rest = text.split(BEGIN, 1)
    _, tail = rest.split(END, 1)
    return head + BEGIN + '\n' + block + '\n' + END + tail


def main(argv):
    if len(argv) == 1:
        print(graph())
        return 0
    if len(argv) == 3 and argv[1] in ('--update', '--check'):
        path = pathlib.Path(argv[2])
        text = path.read_text()
        new = replace_block(text, graph())
        if argv[1] == '--update':
            if new != text:
                path.write_text(new)
            return 0
        errors = layering_errors()
        for error in errors:
            sys.stderr.write('layout_graph.py: %s\n' % error)
        if new != text:
            sys.stderr.write('%s: the layout graph differs from CMake\'s links; run scripts/layout_graph.py '
                             '--update %s\n' % (path, path))
            return 1
        return 1 if errors else 0
    sys.stderr.write(__doc__)
    return 2


if __name__ == '__main__':
    sys.exit(main(sys.argv))
