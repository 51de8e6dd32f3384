"""List the functions in src/ longer than a number of lines of code.

Run: ``.venv/bin/python bench/function_lengths.py [--min 60] [ROOT ...]`` (ROOT defaults to
``src``). A line of code is a line of the function's body that is not blank, not only a
comment and not part of a docstring; a nested function counts towards its enclosing function
and is listed again on its own. Prints ``lines  path:line  qualified.name``, longest first,
and a count at the end.
"""

from __future__ import annotations

import argparse
import ast
import io
import sys
import tokenize
from pathlib import Path


def _docstring_lines(tree: ast.AST) -> set[int]:
    """Line numbers taken by the docstrings of the module, classes and functions."""
    lines: set[int] = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Module | ast.ClassDef | ast.FunctionDef | ast.AsyncFunctionDef):
            body = node.body
            if (
                body
                and isinstance(body[0], ast.Expr)
                and isinstance(body[0].value, ast.Constant)
                and isinstance(body[0].value.value, str)
            ):
                lines.update(range(body[0].lineno, body[0].end_lineno + 1))
    return lines


def _code_lines(source: str) -> set[int]:
    """Line numbers that hold a token other than a comment, a newline or indentation."""
    skip = {tokenize.COMMENT, tokenize.NL, tokenize.NEWLINE, tokenize.INDENT, tokenize.DEDENT}
    skip.add(tokenize.ENDMARKER)
    lines: set[int] = set()
    for token in tokenize.generate_tokens(io.StringIO(source).readline):
        if token.type not in skip:
            lines.update(range(token.start[0], token.end[0] + 1))
    return lines


def function_lengths(path: Path) -> list[tuple[int, int, str]]:
    """``(lines of code, first line, qualified name)`` of every function in one file."""
    source = path.read_text(encoding="utf-8")
    tree = ast.parse(source, filename=str(path))
    code = _code_lines(source) - _docstring_lines(tree)
    found: list[tuple[int, int, str]] = []

    def visit(node: ast.AST, prefix: str) -> None:
        for child in ast.iter_child_nodes(node):
            if isinstance(child, ast.FunctionDef | ast.AsyncFunctionDef):
                name = prefix + child.name
                # the body only: decorators and the signature are not counted
                first = child.body[0].lineno
                count = sum(1 for line in code if first <= line <= child.end_lineno)
                found.append((count, child.lineno, name))
                visit(child, name + ".")
            elif isinstance(child, ast.ClassDef):
                visit(child, prefix + child.name + ".")
            else:
                visit(child, prefix)

    visit(tree, "")
    return found


def main(argv: list[str] | None = None) -> int:
    """List the functions of ROOT (default src) over --min lines of code, longest first."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("roots", nargs="*", default=["src"], help="folders or files to read")
    parser.add_argument("--min", type=int, default=60, help="list functions with more lines of code")
    args = parser.parse_args(argv)
    rows = []
    for root in map(Path, args.roots):
        files = [root] if root.is_file() else sorted(root.rglob("*.py"))
        for path in files:
            rows += [(n, f"{path}:{line}", name) for n, line, name in function_lengths(path) if n > args.min]
    rows.sort(key=lambda row: (-row[0], row[1]))
    for n, where, name in rows:
        print(f"{n:5d}  {where}  {name}")
    print(f"{len(rows)} functions over {args.min} lines of code")
    return 0


if __name__ == "__main__":
    sys.exit(main())
