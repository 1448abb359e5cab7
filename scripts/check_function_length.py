#!/usr/bin/env python3
"""Fails when a C++ function body is longer than the house limit (120 lines).

    scripts/check_function_length.py [--max-lines N] [PATH ...]   (default: the source folders)

Counts the lines between a function's opening and closing brace (blank lines and comments
included), as clang-tidy's readability-function-size LineThreshold does, for every function,
method, constructor and operator defined at namespace or class scope; lambdas count towards
the function that holds them. It is a lexer, not a compiler: comments, string and character
literals (raw strings too) are removed before braces are matched. Exit status 1 lists the
offenders as `file:line: function NAME has N lines (max M)`; 2 on bad usage.
"""

import argparse
import os
import re
import sys

SOURCE_DIRS = ["common", "transport", "agent", "ground_station", "sensors_replay", "tools", "tests"]
EXTENSIONS = (".cpp", ".h", ".hpp", ".cc")
NOT_FUNCTIONS = re.compile(
    r"^\s*(if|for|while|switch|catch|do|else|try|return|namespace|class|struct|union|enum|"
    r"extern)\b")
SCOPES = re.compile(r"\b(namespace|class|struct|union)\b[^()]*$|^\s*extern\s*\"C\"")


def strip_code(text):
    """Blanks comments and literals (keeping newlines) so that only code braces remain."""
    out = []
    i, n = 0, len(text)
    while i < n:
        c = text[i]
        if text.startswith("//", i):
            j = text.find("\n", i)
            i = n if j < 0 else j
        elif text.startswith("/*", i):
            j = text.find("*/", i + 2)
            j = n if j < 0 else j + 2
            out.append("\n" * text.count("\n", i, j))
            i = j
        elif c == "R" and text.startswith('R"', i) and (i == 0 or not text[i - 1].isalnum()):
            m = re.match(r'R"([^(\s]*)\(', text[i:])
            if not m:
                out.append(c)
                i += 1
                continue
            end = text.find(")" + m.group(1) + '"', i)
            j = n if end < 0 else end + len(m.group(1)) + 2
            out.append('""' + "\n" * text.count("\n", i, j))
            i = j
        elif c in "\"'":
            if c == "'" and i > 0 and (text[i - 1].isalnum()):  # digit separator 1'000
                out.append(" ")
                i += 1
                continue
            j = i + 1
            while j < n and text[j] != c and text[j] != "\n":
                j += 2 if text[j] == "\\" else 1
            out.append(c + c)
            i = j + 1
        else:
            out.append(c)
            i += 1
    return "".join(out)


def long_functions(path, max_lines):
    with open(path, encoding="utf-8", errors="replace") as f:
        code = strip_code(f.read())
    code = re.sub(r"^\s*#.*$", "", code, flags=re.M)  # preprocessor lines
    found = []
    stack = []  # per open brace: ("scope" | "function" | "block", start line, name)
    head_start = 0
    line = 1
    for i, c in enumerate(code):
        if c == "\n":
            line += 1
        elif c == "{":
            head = code[head_start:i]
            in_scope = all(kind == "scope" for kind, _, _ in stack)
            if SCOPES.search(head.strip()) and in_scope:
                stack.append(("scope", line, ""))
            elif in_scope and ")" in head and not NOT_FUNCTIONS.match(head) and "=" not in \
                    head.split("(")[0]:
                name = re.findall(r"([~\w:<>]+|operator\S+)\s*\(", head)
                stack.append(("function", line, name[0] if name else "?"))
            else:
                stack.append(("block", line, ""))
            head_start = i + 1
        elif c == "}":
            if stack:
                kind, start, name = stack.pop()
                if kind == "function" and line - start - 1 > max_lines:
                    found.append((start, name, line - start - 1))
            head_start = i + 1
        elif c == ";":
            head_start = i + 1
    return found


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("paths", nargs="*", help="files or folders (default: the source folders)")
    parser.add_argument("--max-lines", type=int, default=120)
    args = parser.parse_args()
    root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    paths = args.paths or [os.path.join(root, d) for d in SOURCE_DIRS
                           if os.path.isdir(os.path.join(root, d))]
    files = []
    for p in paths:
        if os.path.isfile(p):
            files.append(p)
        elif os.path.isdir(p):
            for dirpath, _, names in os.walk(p):
                files += [os.path.join(dirpath, x) for x in names if x.endswith(EXTENSIONS)]
        else:
            print(f"check_function_length: no such file or folder: {p}", file=sys.stderr)
            return 2
    bad = 0
    for path in sorted(files):
        for start, name, lines in long_functions(path, args.max_lines):
            print(f"{os.path.relpath(path, root)}:{start}: function {name} has {lines} lines "
                  f"(max {args.max_lines})")
            bad += 1
    print(f"check_function_length: {len(files)} files, {bad} functions over {args.max_lines} lines")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
