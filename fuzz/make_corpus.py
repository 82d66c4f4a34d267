#!/usr/bin/env python3
"""Builds the fuzzers' seed corpora and the scene dictionary from the repository (docs/fuzzing.md).

Usage: fuzz/make_corpus.py SOURCE_DIR OUT_DIR

Writes (OUT_DIR must not be inside fuzz/seeds; nothing in SOURCE_DIR is written):
  OUT_DIR/scene/  the scene files scenes/*.json (not *.schema.json), every raw string literal
                  R"(...)" in tests/ that is a JSON object (or becomes one after the 4 x 4 grid
                  mesh the scene tests prepend), fuzz/seeds/scene/* and fuzz/regressions/scene/*
  OUT_DIR/obj/    every .obj file git tracks (or, outside git, finds), fuzz/seeds/obj/* and
                  fuzz/regressions/obj/*
  OUT_DIR/scene.dict  a libFuzzer dictionary: every key and string value of those scenes, quoted
Each seed is named by the SHA-1 of its contents (so duplicates collapse), as libFuzzer names its
own corpus files. Prints how many seeds of each kind it wrote.
"""
import glob
import hashlib
import json
import os
import re
import subprocess
import sys

# The scene tests write std::string("{") + kGrid4 + R"(, ...})"; a fragment is completed with it.
GRID4 = '"mesh": {"primitive": "grid", "size": [1.0, 1.0], "divisions": [4, 4]}'


def write_seed(folder, data):
    name = hashlib.sha1(data).hexdigest()
    path = os.path.join(folder, name)
    if os.path.exists(path):
        return 0
    with open(path, "wb") as f:
        f.write(data)
    return 1


def tracked_files(source, pattern):
    try:
        out = subprocess.run(["git", "-C", source, "ls-files", "-z", "--", pattern], check=True,
                             capture_output=True).stdout
        return [os.path.join(source, p) for p in out.decode().split("\0") if p]
    except (OSError, subprocess.CalledProcessError):
        return [p for p in glob.glob(os.path.join(source, "**", pattern), recursive=True)
                if "/build/" not in p and "/out/" not in p]


def test_scenes(source):
    """JSON objects written as raw string literals in tests/ (complete, or after the grid mesh)."""
    scenes = []
    for path in sorted(glob.glob(os.path.join(source, "tests", "**", "*.cpp"), recursive=True)):
        with open(path, encoding="utf-8", errors="replace") as f:
            text = f.read()
        for m in re.finditer(r'R"\((.*?)\)"', text, re.S):
            literal = m.group(1)
            for candidate in (literal, "{" + GRID4 + literal, "{" + GRID4 + ", " + literal + "}"):
                try:
                    value = json.loads(candidate)
                except ValueError:
                    continue
                if isinstance(value, dict):
                    scenes.append(candidate)
                    break
    return scenes


def strings_of(value, out):
    """Every key and string value in a parsed JSON value."""
    if isinstance(value, dict):
        for k, v in value.items():
            out.add(k)
            strings_of(v, out)
    elif isinstance(value, list):
        for v in value:
            strings_of(v, out)
    elif isinstance(value, str) and len(value) <= 40:
        out.add(value)


def dict_entry(token):
    """A libFuzzer dictionary line for the JSON string literal of `token`."""
    quoted = json.dumps(token)
    escaped = "".join(c if 32 <= ord(c) < 127 and c not in '"\\' else "\\x%02x" % b
                      for c in quoted for b in c.encode())
    return '"' + escaped + '"'


def main():
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    source, out = sys.argv[1], sys.argv[2]
    scene_dir, obj_dir = os.path.join(out, "scene"), os.path.join(out, "obj")
    os.makedirs(scene_dir, exist_ok=True)
    os.makedirs(obj_dir, exist_ok=True)

    scenes = []
    scene_files = [p for p in sorted(glob.glob(os.path.join(source, "scenes", "*.json")))
                   if not p.endswith(".schema.json")]
    for path in scene_files + sorted(glob.glob(os.path.join(source, "fuzz", "seeds", "scene", "*"))) + \
            sorted(glob.glob(os.path.join(source, "fuzz", "regressions", "scene", "*"))):
        with open(path, "rb") as f:
            scenes.append(f.read())
    from_tests = test_scenes(source)
    scenes += [s.encode() for s in from_tests]
    n_scene = sum(write_seed(scene_dir, s) for s in scenes)

    objs = tracked_files(source, "*.obj") + sorted(glob.glob(os.path.join(source, "fuzz", "seeds", "obj", "*"))) + \
        sorted(glob.glob(os.path.join(source, "fuzz", "regressions", "obj", "*")))
    n_obj = 0
    for path in sorted(set(objs)):
        # Meshes beyond 100 kB (the body to dress, 866 kB) would raise libFuzzer's input length
        # for every mutation; the small ones cover the same syntax.
        if os.path.getsize(path) > 100_000:
            continue
        with open(path, "rb") as f:
            n_obj += write_seed(obj_dir, f.read())

    tokens = set()
    for s in scenes:
        try:
            strings_of(json.loads(s), tokens)
        except ValueError:
            pass
    with open(os.path.join(out, "scene.dict"), "w") as f:
        f.write("# Keys and string values of the seed scenes (fuzz/make_corpus.py).\n")
        for token in sorted(tokens):
            f.write(dict_entry(token) + "\n")
    print(f"make_corpus: {n_scene} scene seeds ({len(from_tests)} from tests/), {n_obj} OBJ seeds, "
          f"{len(tokens)} dictionary entries in {out}")


if __name__ == "__main__":
    main()
