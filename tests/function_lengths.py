"""The length in lines of every function body in a C++ file, found by matching braces in the text with comments,
strings and character literals blanked out: a function body is an outermost brace block that follows a parameter
list (`) {`, `) const {`, `) -> T {`, a TEST(...) {, a lambda's body when it is not inside a function); blocks of
if/for/while/switch/catch, classes, namespaces and initialisers are not. Used by tests/house_test.py."""
import re

_SIGNATURE_END = re.compile(r"\)\s*(?:const|noexcept|override|final|mutable|->\s*[\w:<>,\s&*]+|\s)*$")
_CONTROL = re.compile(r"\b(?:if|for|while|switch|catch)\s*\([^;{}]*\)\s*$")


def _blank(text):
    """text with comments removed and string/char literals emptied, newlines kept (line numbers hold)."""
    out, i, n = [], 0, len(text)
    while i < n:
        c = text[i]
        if text.startswith("//", i):
            j = text.find("\n", i)
            i = n if j < 0 else j
            continue
        if text.startswith("/*", i):
            j = text.find("*/", i + 2)
            j = n if j < 0 else j + 2
            out.append("\n" * text.count("\n", i, j))
            i = j
            continue
        raw = re.match(r'R"([^(\s]*)\(', text[i:i + 20]) if c == "R" and (i == 0 or not text[i - 1].isalnum()) else None
        if raw:
            end = ")" + raw.group(1) + '"'
            j = text.find(end, i + len(raw.group(0)))
            j = n if j < 0 else j + len(end)
            out.append('""' + "\n" * text.count("\n", i, j))
            i = j
            continue
        if c == '"' or (c == "'" and not (i > 0 and text[i - 1].isalnum())):  # 1'000 is a digit separator
            j = i + 1
            while j < n and text[j] != c and not (c == "'" and text[j] == "\n"):
                j += 2 if text[j] == "\\" else 1
            out.append(c + c)
            i = j + 1
            continue
        out.append(c)
        i += 1
    return "".join(out)


def _name_before(text):
    """The name of the function whose parameter list ends text (the identifier before its matching '(')."""
    depth = 0
    for k in range(len(text) - 1, -1, -1):
        if text[k] == ")":
            depth += 1
        elif text[k] == "(":
            depth -= 1
            if depth == 0:
                m = re.search(r"([\w:~<>]+)\s*$", text[:k])
                return m.group(1) if m else "(lambda)"
    return "?"


def function_lengths(path):
    """[(name, first line, lines)] of the functions in the C++ file at path."""
    text = _blank(open(path, encoding="utf-8", errors="replace").read())
    found, stack, line, start = [], [], 1, None
    for i, c in enumerate(text):
        if c == "\n":
            line += 1
        elif c == "{":
            before = text[max(0, i - 400):i]
            is_function = start is None and _SIGNATURE_END.search(before) and not _CONTROL.search(before)
            if is_function:
                start = (line, len(stack), _name_before(before.rstrip()))
            stack.append(c)
        elif c == "}" and stack:
            stack.pop()
            if start is not None and len(stack) == start[1]:
                found.append((start[2], start[0], line - start[0] + 1))
                start = None
    return found
