#!/usr/bin/env python3
"""Functions fit on a screen: no function body in core/, server/, client/,
proto/ or fuzz/ runs over 80 lines unless the line before it carries a
comment starting `// long:` with the reason, and no .cpp in any of them is
over 400 lines (one rule everywhere, so a class lives in one file). Functions are found by their braces (a line ending in `{` after a
parameter list that is no control statement or lambda), which is what a
reader sees. usage: function_length_test.py SOURCE_DIR
"""
import os
import re
import sys

MAX_FUNCTION_LINES = 80
MAX_FILE_LINES = 400
FOLDERS = ("core", "server", "client", "proto", "fuzz")
CONTROL = re.compile(r"^\s*(\}?\s*else|if|for|while|switch|do|catch|try)\b")
TYPE_OR_SCOPE = re.compile(r"^\s*(namespace|extern|struct|class|enum|union)\b")
LAMBDA = re.compile(r"\]\s*(\(.*\))?\s*(mutable)?\s*(->\s*[\w:<>]+\s*)?\{$")


def strip(line):
    line = re.sub(r'"(\\.|[^"\\])*"', '""', line)
    line = re.sub(r"'(\\.|[^'\\])*'", "''", line)
    return re.sub(r"//.*", "", line)


def long_functions(path):
    lines = open(path, encoding="utf-8").read().split("\n")
    for i, line in enumerate(lines):
        code = strip(line).rstrip()
        if not code.endswith("{") or ")" not in code and "(" not in code:
            continue
        if CONTROL.match(code) or TYPE_OR_SCOPE.match(code) or LAMBDA.search(code):
            continue
        depth, length = 0, 0
        for j in range(i, len(lines)):
            s = strip(lines[j])
            depth += s.count("{") - s.count("}")
            if depth <= 0:
                length = j - i + 1
                break
        reason = i > 0 and lines[i - 1].strip().startswith("// long:")
        if length > MAX_FUNCTION_LINES and not reason:
            yield i + 1, length, line.strip()


def main():
    root = sys.argv[1]
    failures, files = [], 0
    for folder in FOLDERS:
        for dirpath, _, names in os.walk(os.path.join(root, folder)):
            for name in sorted(names):
                if not name.endswith((".cpp", ".h")):
                    continue
                path = os.path.join(dirpath, name)
                rel = os.path.relpath(path, root)
                files += 1
                for line, length, text in long_functions(path):
                    failures.append(f"{rel}:{line}: a {length}-line function: {text[:70]}")
                n = sum(1 for _ in open(path, encoding="utf-8"))
                if name.endswith(".cpp") and n > MAX_FILE_LINES:
                    failures.append(f"{rel}: {n} lines (a .cpp holds one concern, <= 400)")
    for f in failures:
        print("FAIL", f)
    print(f"{files} files read")
    print(f"{1 if not failures else 0} passed, {1 if failures else 0} failed")
    return 1 if failures or files < 100 else 0


if __name__ == "__main__":
    sys.exit(main())
