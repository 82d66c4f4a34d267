#!/usr/bin/env python3
"""Checks scenes against the scene format's JSON Schema (scenes/scene.schema.json).

Usage: check_schema.py SCHEMA [--cases CASES.json] [SCENE.json | FOLDER] ...

- SCHEMA must itself be a valid draft 2020-12 schema;
- every SCENE (and every *.json in a FOLDER, except *.schema.json) must validate;
- CASES (tests/sim/scene/schema_cases.json) is a list of {"name", "valid", "scene"}: each scene
  must validate if "valid" is true and must not if it is false (the scene loader is held to the
  same verdicts by tests/sim/scene/schema_test.cpp).

Prints one line per problem and exits with 1 if there is any, else prints a summary and exits 0.
Needs python3-jsonschema (Debian 12: 4.10), run with /usr/bin/python3.
"""
import argparse
import glob
import json
import os
import sys

try:
    import jsonschema
except ImportError:
    sys.exit("check_schema.py: python3-jsonschema is not installed (scripts/install_deps.sh installs it; "
             "run with /usr/bin/python3)")


def load(path):
    with open(path, encoding="utf-8") as f:
        return json.load(f)


def problems(validator, instance):
    """The validation errors of `instance`, as "at <path>: <message>" lines."""
    out = []
    for error in sorted(validator.iter_errors(instance), key=lambda e: list(e.absolute_path)):
        where = "".join(f"[{p}]" if isinstance(p, int) else f".{p}" for p in error.absolute_path).lstrip(".")
        out.append(f"at {where or '(top level)'}: {error.message}")
    return out


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("schema")
    parser.add_argument("--cases", help="JSON list of {name, valid, scene}")
    parser.add_argument("scenes", nargs="*", help="scene files or folders of them")
    args = parser.parse_intermixed_args()

    schema = load(args.schema)
    jsonschema.Draft202012Validator.check_schema(schema)
    validator = jsonschema.Draft202012Validator(schema)

    files = []
    for item in args.scenes:
        if os.path.isdir(item):
            files += sorted(f for f in glob.glob(os.path.join(item, "*.json")) if not f.endswith(".schema.json"))
        else:
            files.append(item)

    failures = 0
    for path in files:
        for line in problems(validator, load(path)):
            print(f"{path}: {line}")
            failures += 1

    cases = load(args.cases) if args.cases else []
    for case in cases:
        found = problems(validator, case["scene"])
        if case["valid"] and found:
            print(f"{args.cases}: case {case['name']!r} should validate but: {found[0]}")
            failures += 1
        elif not case["valid"] and not found:
            print(f"{args.cases}: case {case['name']!r} should not validate, but does")
            failures += 1

    if failures:
        print(f"check_schema.py: {failures} problem(s)")
        return 1
    print(f"check_schema.py: {len(files)} scene file(s) and {len(cases)} case(s) agree with {args.schema}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
