"""What the safety theorem covers of a workcell, in one rule (``spec.theorem_scope``, docs/model.md
§10), and the parts of a contact in words (``spec.contact_parts``, docs/model.md §2)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import factory
from cfmpa.errors import CertificateViolation
from cfmpa.scenarios import BUNDLED_DIR
from cfmpa.spec import (SCOPE_CHECKED, Certificate, certificate_json, closest_links,
                        contact_links_text, contact_parts, load_scenario, require_clear,
                        theorem_scope)

DATA = Path(__file__).resolve().parents[1] / "data"


@pytest.mark.parametrize("name, scope", [
    ("default", None), ("early-arrival", None), ("limited-joints", None), ("narrow-gap", None),
    ("original-fails", None),
    ("gripper", f"tool: {SCOPE_CHECKED}"),
    ("levels", f"heights: {SCOPE_CHECKED}"),
])
def test_each_bundled_workcell_has_its_scope(name, scope):
    assert theorem_scope(load_scenario(BUNDLED_DIR / f"{name}.toml")) == scope


def test_the_words_say_what_is_not_yet_proved():
    assert SCOPE_CHECKED == ("checked on samples and by the certificate, not yet by the safety "
                             "theorem")
    both = theorem_scope(load_scenario(DATA / "tools-heights.toml"))
    assert both == f"tool and heights: {SCOPE_CHECKED}"
    assert "proved" not in both.replace("not yet by", "")


@pytest.mark.parametrize("changes, what", [
    ({"right__z": [[0.1, 0.2], [0.3, 0.4]]}, "heights"),           # one arm's links alone
    ({"left__tool": {"polygon": [[0, -0.01], [0.05, 0], [0, 0.01]]}}, "tool"),
    ({"left__tool": {"polygon": [[0, -0.01], [0.05, 0], [0, 0.01]], "z": [0.0, 0.1]}},
     "tool and heights"),                                          # a tool's height is a height
    ({}, None),
])
def test_one_arm_with_a_tool_or_a_height_is_enough(changes, what):
    s = factory.scenario(**changes)
    assert theorem_scope(s) == (None if what is None else f"{what}: {SCOPE_CHECKED}")


def test_a_tool_contact_is_named_part_by_part():
    assert contact_parts((3, 3)) == ["left tool", "right tool"]
    assert contact_parts([2, 3]) == ["left link 2 (forearm)", "right tool"]
    assert contact_links_text((1, 3)) == "left link 1 (upper arm) and right tool"
    d = np.ones((3, 2))
    d[2, 1] = 0.0                                   # array index (2, 1): left tool, right link 2
    assert closest_links(d) == (3, 2)
    assert contact_links_text(closest_links(d)) == "left tool and right link 2 (forearm)"


def _touching(links: tuple[int, int]) -> Certificate:
    return Certificate(clear=False, min_clearance_m=0.0, t_min_s=0.5, lower_bound_m=0.0,
                       intervals=3, contact=(0.5, links), undecided=(), samples=4,
                       max_depth_used=1)


def test_the_certificate_json_and_violation_name_the_tool():
    js = certificate_json(_touching((3, 3)))["contact"]
    assert js["links"] == [3, 3] and js["parts"] == ["left tool", "right tool"]
    assert js["links_text"] == "left tool and right tool"
    with pytest.raises(CertificateViolation) as e:
        require_clear(_touching((3, 3)))
    # A tool is no link rectangle: the message says parts, and names them.
    assert "the arms' parts touch" in str(e.value) and "left tool and right tool" in str(e.value)
    with pytest.raises(CertificateViolation) as e:
        require_clear(_touching((2, 2)))
    assert "the arms' link rectangles touch" in str(e.value) and "tool" not in str(e.value)
    assert certificate_json(_touching((2, 2)))["contact"]["parts"] == [
        "left link 2 (forearm)", "right link 2 (forearm)"]
