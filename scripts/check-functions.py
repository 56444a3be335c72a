#!/usr/bin/env python3
"""Fails when a C++ function outside tests/ is longer than --max lines (80) without a reason:
a comment line starting `// Long:` among the comment lines right above its signature. Long
drivers are split into options, grid, run and write (house style); what stays long says why.

    scripts/check-functions.py [--max 80] [--list]

--list prints every function over the limit, reasons included. Functions are found by brace
matching over the code with comments and literals removed: a `{` at namespace or class scope
whose head (the text since the last `;`, `{` or `}`) has a parenthesis opens a function (a
lambda at namespace scope counts as one)."""
import argparse
import os
import re
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def strip(text):
    """The text with comments, string and character literals blanked, newlines kept."""
    out = []
    i, n = 0, len(text)
    while i < n:
        c = text[i]
        if text.startswith("//", i):
            j = text.find("\n", i)
            j = n if j < 0 else j
            out.append(" " * (j - i))
            i = j
        elif text.startswith("/*", i):
            j = text.find("*/", i + 2)
            j = n if j < 0 else j + 2
            out.append(re.sub(r"[^\n]", " ", text[i:j]))
            i = j
        elif text.startswith('R"', i):
            m = re.match(r'R"([^(]*)\(', text[i:])
            end = text.find(")" + m.group(1) + '"', i) if m else -1
            j = n if end < 0 else end + len(m.group(1)) + 2
            out.append('""' + re.sub(r"[^\n]", " ", text[i + 2:j]))
            i = j
        elif c in "\"'":
            j = i + 1
            while j < n and text[j] != c:
                j += 2 if text[j] == "\\" else 1
            out.append(c + " " * (j - i - 1) + c)
            i = j + 1
        else:
            out.append(c)
            i += 1
    return "".join(out)


def functions(text):
    """(first line, last line, signature head) of every function body, 1-based lines."""
    code = strip(text)
    found = []
    stack = []  # each: kind ("scope" or "function" or "block"), start line, head
    last = 0  # index after the last ; { or }
    line = 1
    for i, c in enumerate(code):
        if c == "\n":
            line += 1
        elif c == "{":
            head = code[last:i]
            outer = all(kind == "scope" for kind, _, _ in stack)
            if re.search(r"\b(namespace|class|struct|union|enum)\b", head) and "(" not in head:
                kind = "scope"
            elif re.search(r"\bextern\s+\"", head):
                kind = "scope"
            elif outer and "(" in head:
                kind = "function"
            else:
                kind = "block"
            # The head's first line: where its first character is (comments are blank).
            prefix = head[:len(head) - len(head.lstrip())]
            stack.append((kind, line - head.count("\n") + prefix.count("\n"), head))
            last = i + 1
        elif c == "}":
            if stack:
                kind, start, head = stack.pop()
                if kind == "function":
                    found.append((start, line, " ".join(head.split())))
            last = i + 1
        elif c == ";":
            last = i + 1
    return found


def reason(lines, start):
    """The `// Long:` reason in the comment block above line `start` (1-based), or None."""
    i = start - 2
    while i >= 0 and (lines[i].strip().startswith("//") or lines[i].strip().startswith("template")):
        if lines[i].strip().startswith("// Long:"):
            return lines[i].strip()[len("// Long:"):].strip()
        i -= 1
    return None


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--max", type=int, default=80)
    parser.add_argument("--list", action="store_true")
    args = parser.parse_args()
    files = subprocess.run(["git", "ls-files", "-co", "--exclude-standard", "*.cpp", "*.h"],
                           cwd=ROOT, check=True, capture_output=True, text=True).stdout.split()
    bad = 0
    for path in sorted(f for f in files if not f.startswith("tests/")):
        full = os.path.join(ROOT, path)
        if not os.path.exists(full):
            continue
        with open(full) as f:
            text = f.read()
        lines = text.split("\n")
        for start, end, head in functions(text):
            length = end - start + 1
            if length <= args.max:
                continue
            why = reason(lines, start)
            name = re.sub(r"\s*\(.*", "", head.split("\n")[-1]).split()[-1] if head else "?"
            if why is None:
                bad += 1
                print(f"{path}:{start}: {name} is {length} lines (over {args.max}; split it, "
                      "or say why above it: // Long: ...)")
            elif args.list:
                print(f"{path}:{start}: {name} is {length} lines: {why}")
    if bad:
        sys.exit(1)
    print(f"check-functions: no function outside tests/ over {args.max} lines without a reason")


if __name__ == "__main__":
    main()
