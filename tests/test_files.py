"""cfmpa.files' one JSON writer: its styles give the bytes each file had."""

from __future__ import annotations

import json
import math
from pathlib import Path

import pytest

from cfmpa.files import JsonStyle, dumps_json, write_json

ROOT = Path(__file__).resolve().parents[1]
DOC = {"b": [1, 2.5, None], "a": {"δ": "c − 2 L δ", "z": True}}


def test_each_style_is_the_layout_its_files_had():
    assert dumps_json(DOC) == json.dumps(DOC, indent=2, sort_keys=True) + "\n"
    assert dumps_json(DOC, JsonStyle.LOCK, ascii_only=False) == (
        json.dumps(DOC, indent=1, sort_keys=True, ensure_ascii=False) + "\n")
    assert dumps_json(DOC, JsonStyle.LINE) == (
        '{"a":{"z":true,"\\u03b4":"c \\u2212 2 L \\u03b4"},"b":[1,2.5,null]}\n')


def test_the_pinned_lock_is_written_as_it_reads():
    # obligations.lock is rewritten by `cfmpa prove --repin` through write_json: a re-pin of the
    # same pins must give the same bytes (a layout change would show as a diff of every line).
    raw = (ROOT / "proofs" / "obligations.lock").read_text(encoding="utf-8")
    assert dumps_json(json.loads(raw), JsonStyle.LOCK, ascii_only=False, allow_nan=True) == raw


def test_nan_is_refused_unless_allowed_and_the_write_is_whole(tmp_path):
    with pytest.raises(ValueError, match="not JSON compliant: nan"):
        dumps_json({"x": math.nan})
    assert dumps_json({"x": math.nan}, allow_nan=True) == '{\n  "x": NaN\n}\n'
    path = write_json(tmp_path / "d" / "x.json", DOC)
    assert json.loads(path.read_text(encoding="utf-8")) == DOC
    assert [p.name for p in path.parent.iterdir()] == ["x.json"]     # no temporary left
