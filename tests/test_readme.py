"""The README for users: its command synopsis is the parser's, and it stays short.

The synopsis is the first ``sh`` block under "## Commands": one ``cfmpa COMMAND ...`` line per
form, continued on indented lines. It is compared with ``cfmpa.cli._parser()`` both ways: every
subcommand appears, every option named for a subcommand is one of its options, and every option
of a subcommand is named (or listed in ``NOT_IN_SYNOPSIS`` with its reason). When the parser
gains an option, the failure names it: add it to the README.
"""

from __future__ import annotations

import argparse
import re
from pathlib import Path

from cfmpa._arguments import visible_options
from cfmpa.cli import _parser

README = Path(__file__).resolve().parents[1] / "README.md"
MAX_WORDS = 1500

#: Options that need not be in the synopsis, each with its reason ("*": every subcommand).
NOT_IN_SYNOPSIS: dict[str, set[str]] = {
    "*": {"--help"},             # argparse's own; the README says `cfmpa COMMAND --help`
    # A ROS 2 bag's options: the README is at its 1,500 words, so they are in
    # `cfmpa COMMAND --help` and docs/model.md §12 only.
    "certify": {"--topic", "--joints", "--t0"},
    "monitor": {"--topic", "--joints", "--t0", "--allow-gaps"},
    "simulate": {"--topic", "--joints"},
}

_OPTION = re.compile(r"(?<![\w-])--[a-z][a-z0-9-]*")


def synopsis(text: str) -> str:
    """The first ```sh block after the "## Commands" heading."""
    section = text.split("\n## Commands\n", 1)[1].split("\n## ", 1)[0]
    return section.split("```sh\n", 1)[1].split("```", 1)[0]


def synopsis_forms(block: str) -> dict[str, set[str]]:
    """Subcommand -> the options its forms name (comments after `#` left out); the top-level
    form `cfmpa --version` is kept under ""."""
    forms: dict[str, set[str]] = {}
    current: str | None = None
    for line in block.splitlines():
        code = line.split("#", 1)[0].rstrip()
        if not code.strip():
            continue
        if code.startswith("cfmpa "):
            words = code.split()
            current = "" if words[1].startswith("-") else words[1]
            forms.setdefault(current, set())
        elif current is None or not code.startswith(" "):
            raise AssertionError(f"synopsis line is neither `cfmpa ...` nor a continuation: {line!r}")
        forms[current] |= set(_OPTION.findall(code))
    return forms


def parser_options(parser: argparse.ArgumentParser) -> dict[str, set[str]]:
    """Subcommand -> its long options as its help shows them; "" -> the top-level parser's.
    Old spellings (hidden from the help, docs/model.md §7.6) are not in the synopsis either."""
    out = {"": {o for a in parser._actions for o in visible_options(a) if o.startswith("--")}}
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            for name, sub in action.choices.items():
                out[name] = {o for a in sub._actions for o in visible_options(a)
                             if o.startswith("--")}
    return out


def synopsis_problems(block: str, parser: argparse.ArgumentParser) -> list[str]:
    """Every way the synopsis and the parser disagree, one message each ([] when they agree)."""
    forms = synopsis_forms(block)
    have = parser_options(parser)
    problems = []
    for name in sorted(set(have) - {""} - set(forms)):
        problems.append(f"cfmpa {name}: a subcommand of the parser, missing from the synopsis")
    for name in sorted(set(forms) - set(have)):
        problems.append(f"cfmpa {name}: in the synopsis, not a subcommand of the parser")
    for name in sorted(set(forms) & set(have)):
        label = f"cfmpa {name}".rstrip()
        for opt in sorted(forms[name] - have[name]):
            problems.append(f"{label}: the synopsis names {opt}, which the parser does not have")
        allowed = NOT_IN_SYNOPSIS["*"] | NOT_IN_SYNOPSIS.get(name, set())
        for opt in sorted(have[name] - forms[name] - allowed):
            problems.append(f"{label}: the parser has {opt}, missing from the synopsis")
    return problems


def word_count_problem(text: str) -> str | None:
    """Why the README is too long, or None; words as `wc -w` counts them."""
    words = len(text.split())
    return f"README.md has {words} words, more than {MAX_WORDS}" if words > MAX_WORDS else None


def test_the_synopsis_matches_the_parser():
    problems = synopsis_problems(synopsis(README.read_text()), _parser())
    assert problems == [], "README.md's synopsis has drifted from cfmpa/cli.py:\n" + "\n".join(
        problems)


def test_every_subcommand_has_a_form():
    forms = synopsis_forms(synopsis(README.read_text()))
    assert set(parser_options(_parser())) - {""} <= set(forms)
    assert {"plan", "check", "prove", "certify", "monitor"} <= set(forms)   # not an empty read


def test_the_readme_is_at_most_1500_words():
    problem = word_count_problem(README.read_text())
    assert problem is None, problem


# --- seeded faults: each drift is reported, naming the subcommand and the option ---------------
# Compared with the unplanted synopsis's own problems, so that a drift someone else introduced
# shows in test_the_synopsis_matches_the_parser alone.

def _block() -> str:
    return synopsis(README.read_text())


def _new_problems(block: str, parser: argparse.ArgumentParser | None = None) -> list[str]:
    before = set(synopsis_problems(_block(), _parser()))
    return [x for x in synopsis_problems(block, parser or _parser()) if x not in before]


def test_an_old_spelling_in_the_synopsis_is_reported():
    block = _block()
    assert "[--witness-out FILE]" in block
    planted = block.replace("[--witness-out FILE]", "[--witness FILE]")
    assert _new_problems(planted) == [
        "cfmpa plan: the synopsis names --witness, which the parser does not have",
        "cfmpa plan: the parser has --witness-out, missing from the synopsis"]


def test_an_option_dropped_from_the_synopsis_is_reported():
    block = _block()
    assert "[--json OUT] [--allow-speed]" in block
    planted = block.replace("cfmpa certify SCENARIO --traj FILE [--json OUT] [--allow-speed]",
                            "cfmpa certify SCENARIO --traj FILE [--allow-speed]")
    assert planted != block
    assert _new_problems(planted) == [
        "cfmpa certify: the parser has --json, missing from the synopsis"]


def test_an_option_the_parser_lacks_is_reported():
    planted = _block().replace("cfmpa dr SCENARIO --out DIR", "cfmpa dr SCENARIO --out DIR --fast")
    assert _new_problems(planted) == [
        "cfmpa dr: the synopsis names --fast, which the parser does not have"]


def test_an_option_new_in_the_parser_is_reported():
    p = _parser()
    for action in p._actions:
        if isinstance(action, argparse._SubParsersAction):
            action.choices["monitor"].add_argument("--planted-option", type=float)
    assert _new_problems(_block(), p) == [
        "cfmpa monitor: the parser has --planted-option, missing from the synopsis"]


def test_a_missing_subcommand_is_reported():
    block = "".join(line + "\n" for line in _block().splitlines()
                    if not line.startswith("cfmpa scenarios"))
    assert _new_problems(block) == [
        "cfmpa scenarios: a subcommand of the parser, missing from the synopsis"]


def test_an_option_in_a_comment_does_not_count():
    block = _block().replace("[--json OUT] [--allow-speed]", "[--allow-speed]  # --json OUT", 1)
    assert _new_problems(block) == [
        "cfmpa certify: the parser has --json, missing from the synopsis"]


def test_the_word_count_check_fails_on_a_longer_readme():
    text = README.read_text()
    padded = text + " word" * (MAX_WORDS + 1 - len(text.split()))     # one word too many
    assert word_count_problem(padded) == f"README.md has {MAX_WORDS + 1} words, more than 1500"
