#!/usr/bin/env python3
"""Tests of .ci/layers.py: scratch copies of src/ and docs/, each with one deliberate change,
and the status the checker must give them (1: an offence found, 0: none).

usage: python3 .ci/test_layers.py   (from the repository's root)
"""

import os
import shutil
import subprocess
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
CHECKER = os.path.join(ROOT, ".ci", "layers.py")


def append(path, text):
    with open(path, "a", encoding="utf-8") as f:
        f.write(text)


def prepend(path, text):
    with open(path, encoding="utf-8") as f:
        old = f.read()
    with open(path, "w", encoding="utf-8") as f:
        f.write(text + old)


def replace(path, old, new):
    with open(path, encoding="utf-8") as f:
        text = f.read()
    if old not in text:
        raise SystemExit(f"test_layers: {path} no longer holds {old!r}; update the test")
    with open(path, "w", encoding="utf-8") as f:
        f.write(text.replace(old, new, 1))


def new_module(_):
    with open("src/newmod.rs", "w", encoding="utf-8") as f:
        f.write("//! A module in no layer.\n")
    replace("src/lib.rs", "mod status;", "mod status;\nmod newmod;")


CASES = [
    ("unchanged", 0, lambda _: None),
    ("upward use", 1, lambda _: prepend("src/system/layout.rs", "use crate::branches::Request;\n")),
    (
        "upward use in a use tree",
        1,
        lambda _: prepend(
            "src/verify/grid.rs", "use crate::{bar::Bar, stability::{StabilityOptions, Verdict}};\n"
        ),
    ),
    (
        "upward qualified path in code",
        1,
        lambda _: append(
            "src/forced/point.rs",
            "\nfn f() -> crate::exact::ExactOptions { crate::exact::ExactOptions::default() }\n",
        ),
    ),
    (
        "upward path through super::",
        1,
        lambda _: append(
            "src/modal/character.rs", "\nfn f() { let _ = super::super::solution::Solution::new; }\n"
        ),
    ),
    (
        "upward serde attribute path",
        1,
        lambda _: replace(
            "src/continuation/driver.rs",
            '"crate::error::display"',
            '"crate::io::write_backbone_csv"',
        ),
    ),
    (
        "a lower item named through a higher module's re-export",
        0,
        lambda _: replace(
            "src/continuation/mod.rs", "use crate::verdict::Crossing;", "use crate::stability::Crossing;"
        ),
    ),
    ("upward pub use", 1, lambda _: append("src/solve/mod.rs", "\npub use crate::sweep::backbones;\n")),
    (
        "circle between two files",
        1,
        lambda _: prepend("src/continuation/arclength/bracket.rs", "use super::Arclength;\n"),
    ),
    (
        "circle through a qualified path",
        1,
        lambda _: append(
            "src/io/assembly/format.rs", "\nfn f() { let _ = super::named::Assembly::system; }\n"
        ),
    ),
    ("module in no layer", 1, new_module),
    (
        "comments, strings and cfg(test) items left out",
        0,
        lambda _: append(
            "src/system/layout.rs",
            "\n// crate::branches::Request\nconst S: &str = \"crate::branches::Request\";\n"
            "#[cfg(test)]\nmod tests {\n    use crate::branches::Request;\n}\n",
        ),
    ),
]


def main():
    failures = 0
    for name, expected, edit in CASES:
        with tempfile.TemporaryDirectory() as scratch:
            for part in ("src", "docs"):
                shutil.copytree(os.path.join(ROOT, part), os.path.join(scratch, part))
            here = os.getcwd()
            os.chdir(scratch)
            try:
                edit(scratch)
            finally:
                os.chdir(here)
            run = subprocess.run(
                [sys.executable, CHECKER, "--root", scratch], capture_output=True, text=True
            )
        ok = run.returncode == expected
        failures += not ok
        first = (run.stdout.splitlines() or [""])[0].replace(scratch + os.sep, "")
        print(f"{'ok' if ok else 'FAILED'}: {name}: status {run.returncode}, {first}")
    if failures:
        print(f"test_layers: {failures} of {len(CASES)} cases failed")
        return 1
    print(f"test_layers: {len(CASES)} cases")
    return 0


if __name__ == "__main__":
    sys.exit(main())
