#!/usr/bin/env python3
"""Turns scripts/checks.json and scripts/checks/*.json (the registry of asval's checks) into docs/coverage.md.

The registry names, for every VUID the layer checks or has decided it cannot check, its family (a flag of
the enabled_checks setting in scripts/settings.json), its status and the tests that exercise it. This
script checks the registry against the VUIDs of the specification chapter (scripts/vuids_newer.json), the
families, and the test sources, then writes the coverage table. --verify (run by CTest) exits non-zero
when the registry is inconsistent or docs/coverage.md is stale.

A checked VUID names its firing test first. That test's expectations (Expect..., CHECK, REQUIRE) must name
the VUID, in full or by its suffix (pInfos-03710), in the test body or through what the body uses from its
own file: a constant (kVuid), a table (Rules()), a local set from one, or a helper's own expectations. This
is read from the source text, not compiled: a test that names the VUID only in a comment, or only in a
statement that expects nothing, does not count.
"""
import argparse
import json
import os
import re
import sys
from collections import Counter, OrderedDict

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
STATUSES = OrderedDict([
    ("checked", "checked"),
    ("partial", "partly checked"),
    ("not-checkable", "not checkable"),
])


def load_json(relative):
    with open(os.path.join(ROOT, relative), encoding="utf-8") as f:
        return json.load(f)


def families():
    settings = load_json("scripts/settings.json")
    for setting in settings["settings"]:
        if setting["key"] == "enabled_checks":
            return OrderedDict((flag["key"], flag["label"]) for flag in setting["flags"])
    raise SystemExit("gen_checks: scripts/settings.json has no enabled_checks setting")


def spec_vuids():
    data = load_json("scripts/vuids_newer.json")
    newest = set(data["chapter_vuids"])
    older = {old: new for new, olds in data["aliases"].items() for old in olds}
    return newest, older


def test_sources():
    texts = {}
    for directory, _, files in os.walk(os.path.join(ROOT, "tests")):
        for name in files:
            if name.endswith((".cpp", ".h")):
                path = os.path.join(directory, name)
                with open(path, encoding="utf-8") as f:
                    texts[os.path.relpath(path, ROOT)] = f.read()
    return texts


def blank(text, strings=False):
    """The text with every comment blanked, and with strings also the contents of string and character
    literals (same length, newlines kept): a VUID in a comment never counts, and the shape of the code
    (brackets, declarations) is read where no literal can fool it."""
    out, i, n = list(text), 0, len(text)
    while i < n:
        c = text[i]
        if c in "\"'":
            start = i + 1
            i += 1
            while i < n and text[i] != c:
                i += 2 if text[i] == "\\" else 1
            if strings:
                out[start:i] = " " * (i - start)
            i += 1
        elif text.startswith("//", i):
            end = text.find("\n", i)
            end = n if end < 0 else end
            out[i:end] = " " * (end - i)
            i = end
        elif text.startswith("/*", i):
            end = text.find("*/", i + 2)
            end = n if end < 0 else end + 2
            out[i:end] = [ch if ch == "\n" else " " for ch in text[i:end]]
            i = end
        else:
            i += 1
    return "".join(out)


def matching(shape, open_pos):
    """Index just past the bracket that closes the one at open_pos, in text whose literals are blanked."""
    pairs = {"{": "}", "(": ")", "[": "]"}
    stack = []
    for i in range(open_pos, len(shape)):
        c = shape[i]
        if c in pairs:
            stack.append(pairs[c])
        elif c in ")}]":
            if not stack or stack.pop() != c:
                return None
            if not stack:
                return i + 1
    return None


class TestCase:
    """One TEST_CASE: the file it sits in, as code (comments blanked) and as shape (literals blanked too),
    and where its body is in them."""

    def __init__(self, path, code, shape, body_start, body_end):
        self.path, self.code, self.shape = path, code, shape
        self.body_start, self.body_end = body_start, body_end

    @property
    def body(self):
        return self.code[self.body_start:self.body_end]


def test_cases(sources):
    """Every TEST_CASE by name (adjacent string literals joined as the compiler joins them)."""
    cases = {}
    literal = re.compile(r'\s*"((?:[^"\\]|\\.)*)"')
    for path, text in sources.items():
        code, shape = blank(text), blank(text, strings=True)
        for start in re.finditer(r"\bTEST_CASE\(", shape):
            pos, name = start.end(), ""
            while True:
                match = literal.match(code, pos)
                if not match:
                    break
                name += match.group(1)
                pos = match.end()
            if not name:
                continue
            close = matching(shape, start.end() - 1)
            brace = shape.find("{", close) if close else -1
            end = matching(shape, brace) if brace >= 0 else None
            cases[name] = TestCase(path, code, shape, brace, end or brace)
    return cases


def test_case_names(sources):
    return {name: case.path for name, case in test_cases(sources).items()}


IDENTIFIER = re.compile(r"\b[A-Za-z_]\w*\b")
# A finding is expected through the monitor (Expect, ExpectEachCommand...), or by comparing what was reported.
EXPECTATION = re.compile(r"\b(?:\w*Expect\w*|CHECK\w*|REQUIRE\w*)\s*\(")


_definitions = {}  # (path, name) -> text: many tests of one file use the same names


def definition(case, name, outside):
    """The text of the definition of name in the test's file outside test bodies (a constant, a table, a
    function, a struct), or ''. outside: the (start, end) ranges of the file's test bodies."""
    key = (case.path, name)
    if key not in _definitions:
        _definitions[key] = find_definition(case.shape, case.code, name, outside)
    return _definitions[key]


def find_definition(shape, code, name, outside):
    pattern = re.compile(r"\b(?:struct\s+|class\s+)?" + re.escape(name) +
                         r"\b\s*(?:\[[^\]]*\]\s*)?(=|\{|\((?=[^;{}]*\)\s*(?:const\s*)?(?:->[^{;]*)?\{))")
    for match in pattern.finditer(shape):
        if any(start <= match.start() < end for start, end in outside):
            continue
        before = shape[max(0, match.start() - 80):match.start()].rstrip()
        declared = re.search(r"(?:[\w*&>]|\bstruct|\bclass)$", before)
        if not declared or re.search(r"(?:->|::|\b(?:return|case|namespace))$", before):
            continue  # no type before it: a use (an argument, a member, an assignment, a return)
        if match.group(1) == "=":
            # Up to the ';' that ends it, or to the bracket that closes around it (a parameter's default).
            depth, i = 0, match.end()
            while i < len(shape) and not (depth == 0 and shape[i] in ";,") and depth >= 0:
                depth += 1 if shape[i] in "([{" else -1 if shape[i] in ")]}" else 0
                i += 1
            return code[match.start():i]
        open_pos = shape.find("{", match.start()) if match.group(1) == "(" else match.start(1)
        close = matching(shape, open_pos)
        return code[match.start():close or len(code)]
    return ""


def statements(text):
    """The text cut at ';', '{' and '}' outside parentheses (so a CHECK holding a braced list stays whole):
    close enough to C++ statements for finding expectations."""
    parts, start, depth, i, n = [], 0, 0, 0, len(text)
    while i < n:
        c = text[i]
        if c in "\"'":
            i += 1
            while i < n and text[i] != c:
                i += 2 if text[i] == "\\" else 1
        elif c in "([":
            depth += 1
        elif c in ")]":
            depth = max(0, depth - 1)
        elif c in ";{}" and depth == 0:
            parts.append(text[start:i])
            start = i + 1
        i += 1
    parts.append(text[start:])
    return [part for part in parts if part.strip()]


def local_values(body, name):
    """The statements of a test body that give the local name a value: its declaration (a for-loop header
    included), assignments, and push_back/emplace_back into it."""
    value = re.compile(r"(?:[\w*&>]\s+" + re.escape(name) + r"\s*[:=({\[]|(?<![\w.>])" + re.escape(name) +
                       r"\s*(?:=(?!=)|\.(?:push_back|emplace_back)\s*\())")
    return "\n".join(statement for statement in statements(body) if value.search(statement))


def expected_text(case, bodies, depth=3):
    """What the firing test's expectations (Expect..., CHECK, REQUIRE) can name: the expectation statements of
    its body; the definitions of the names they use (a constant such as kVuid, a table such as Rules(),
    through a local such as a loop variable); and the expectations inside the file's helpers that the body
    calls. Followed depth levels deep, within the test's own file."""
    found, seen_values, seen_code = [], set(), set()
    code, values = [case.body], []  # code: only its expectations count; values: all they hold can be expected
    for _ in range(depth):
        names, helpers = set(), set()
        for text in values:
            names |= set(IDENTIFIER.findall(text))
        for text in code:
            for statement in statements(text):
                if EXPECTATION.search(statement):
                    found.append(statement)
                    names |= set(IDENTIFIER.findall(statement))
                else:
                    helpers |= set(IDENTIFIER.findall(statement))
        code, values = [], []
        for name in sorted(names - seen_values):
            seen_values.add(name)
            text = definition(case, name, bodies) or local_values(case.body, name)
            if text:
                found.append(text)
                values.append(text)
        for name in sorted(helpers - seen_code):
            seen_code.add(name)
            text = definition(case, name, bodies)
            if text:
                code.append(text)
        if not code and not values:
            break
    return "\n".join(found)


def mentions(text, vuid):
    """vuid in full, or its suffix after the command or structure name (e.g. pInfos-03710), as a whole word."""
    suffix = vuid.split("-", 2)[2]
    return re.search(r"(?<![\w-])(?:" + re.escape(vuid) + "|" + re.escape(suffix) + r")(?![\w-])", text) is not None


def firing_test_problem(vuid, test, case, bodies):
    """Why the firing test does not really expect vuid, or None when it does."""
    if not EXPECTATION.search(case.body):
        return f"its firing test {test!r} ({case.path}) expects no finding (no Expect/CHECK/REQUIRE)"
    if not mentions(expected_text(case, bodies), vuid):
        return (f"its firing test {test!r} ({case.path}) expects findings but never {vuid} (nor its suffix): no "
                f"Expect/CHECK/REQUIRE in its body, or in its file's helpers it calls, names it directly or "
                f"through a constant or table")
    return None


def validate(registry, family_names, newest, older, sources):
    errors = []
    cases = test_cases(sources)
    names = {name: case.path for name, case in cases.items()}
    bodies = {}
    for case in cases.values():
        bodies.setdefault(case.path, []).append((case.body_start, case.body_end))
    seen = set()
    for entry in registry["checks"]:
        vuid = entry["vuid"]
        where = f"checks.json entry {vuid}"
        if vuid in seen:
            errors.append(f"{where}: listed twice")
        seen.add(vuid)
        if vuid not in newest and vuid not in older:
            errors.append(f"{where}: not a VUID of the chapter (scripts/vuids_newer.json)")
        if vuid in older:
            errors.append(f"{where}: an older spelling; use {older[vuid]}")
        if not any(vuid.startswith(prefix) for prefix in registry["scope"]):
            errors.append(f"{where}: outside the scope prefixes")
        if entry.get("family") not in family_names:
            errors.append(f"{where}: unknown family {entry.get('family')!r} (enabled_checks flags)")
        status = entry.get("status")
        if status not in STATUSES:
            errors.append(f"{where}: status must be one of {', '.join(STATUSES)}")
        if status in ("partial", "not-checkable") and not entry.get("note"):
            errors.append(f"{where}: a {status} entry needs a note saying why")
        for test in entry.get("tests", []):
            if test not in names:
                errors.append(f"{where}: no TEST_CASE named {test!r} under tests/")
        if status == "checked":
            if len(entry.get("tests", [])) < 2:
                errors.append(f"{where}: a checked VUID needs a firing test and a valid twin")
            if not any(vuid in text for text in sources.values()):
                errors.append(f"{where}: no test source names this VUID")
            firing = (entry.get("tests") or [None])[0]
            if firing in cases:
                problem = firing_test_problem(vuid, firing, cases[firing], bodies[cases[firing].path])
                if problem:
                    errors.append(f"{where}: {problem}")
    return errors


def render(registry, family_names, newest):
    in_scope = sorted(v for v in newest if any(v.startswith(p) for p in registry["scope"]))
    entries = {e["vuid"]: e for e in registry["checks"]}
    lines = [
        "# Coverage: which Valid Usage rules asval checks",
        "",
        "Generated by `scripts/gen_checks.py` from `scripts/checks.json`; do not edit. Every VUID of the",
        "specification chapter's acceleration-structure build, copy and property commands (and their",
        "structures) is listed with its status. *not yet* means no issue has implemented it so far.",
        "A family can be switched off with the `enabled_checks` setting.",
        "",
        "## Summary",
        "",
        "| scope | VUIDs | checked | partly | not checkable | not yet |",
        "|---|---|---|---|---|---|",
    ]
    for prefix in registry["scope"]:
        group = [v for v in in_scope if v.startswith(prefix)]
        if not group:
            continue
        counts = Counter(entries[v]["status"] if v in entries else "not-yet" for v in group)
        label = prefix[len("VUID-"):].rstrip("-")
        lines.append(f"| `{label}` | {len(group)} | {counts['checked']} | {counts['partial']} | "
                     f"{counts['not-checkable']} | {counts['not-yet']} |")
    total = Counter(entries[v]["status"] if v in entries else "not-yet" for v in in_scope)
    lines.append(f"| **all** | {len(in_scope)} | {total['checked']} | {total['partial']} | "
                 f"{total['not-checkable']} | {total['not-yet']} |")
    lines += ["", "## By family", ""]
    for key, label in family_names.items():
        members = [e for e in registry["checks"] if e["family"] == key]
        lines.append(f"- **{label}** (`{key}`): {len(members)} listed, "
                     f"{sum(1 for e in members if e['status'] == 'checked')} checked")
    lines += ["", "## Every VUID", "", "| VUID | family | status | tests / notes |", "|---|---|---|---|"]
    for vuid in in_scope:
        entry = entries.get(vuid)
        if not entry:
            lines.append(f"| `{vuid}` | | not yet | |")
            continue
        details = "; ".join(f"`{t}`" for t in entry.get("tests", []))
        if entry.get("note"):
            details = (details + ". " if details else "") + entry["note"]
        lines.append(f"| `{vuid}` | {entry['family']} | {STATUSES[entry['status']]} | {details} |")
    return "\n".join(lines) + "\n"


def main():
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--verify", action="store_true", help="fail if the registry is wrong or the doc stale")
    args = parser.parse_args()
    registry = load_json("scripts/checks.json")
    registry["checks"] = []
    for name in sorted(os.listdir(os.path.join(ROOT, "scripts", "checks"))):
        if name.endswith(".json"):
            registry["checks"] += load_json(os.path.join("scripts", "checks", name))
    family_names = families()
    newest, older = spec_vuids()
    errors = validate(registry, family_names, newest, older, test_sources())
    for error in errors:
        print(f"gen_checks: {error}", file=sys.stderr)
    if errors:
        return 1
    text = render(registry, family_names, newest)
    path = os.path.join(ROOT, "docs", "coverage.md")
    if args.verify:
        current = open(path, encoding="utf-8").read() if os.path.exists(path) else ""
        if current != text:
            print("gen_checks: docs/coverage.md is stale; run scripts/gen_checks.py", file=sys.stderr)
            return 1
        return 0
    with open(path, "w", encoding="utf-8") as f:
        f.write(text)
    print("gen_checks: wrote docs/coverage.md")
    return 0


if __name__ == "__main__":
    sys.exit(main())
