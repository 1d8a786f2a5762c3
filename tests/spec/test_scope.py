"""What the safety theorem covers of a workcell, in one rule (``spec.theorem_scope``, docs/model.md
§10), and the parts of a contact in words (``spec.contact_parts``, docs/model.md §2)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import factory
from cfmpa.errors import CertificateViolation
from cfmpa.scenarios import BUNDLED_DIR
from cfmpa.spec import (
    Certificate,
    certificate_json,
    closest_links,
    contact_links_text,
    contact_parts,
    load_scenario,
    require_clear,
    theorem_scope,
)
from cfmpa.spec._scope import SCOPE_CHECKED

DATA = Path(__file__).resolve().parents[1] / "data"


@pytest.mark.parametrize("name", ["default", "early-arrival", "limited-joints", "narrow-gap",
                                  "original-fails", "gripper", "levels"])
def test_the_theorem_covers_every_bundled_workcell(name):
    # Tools (gripper) and heights (levels) included: the compositions range over every pair of
    # parts the height rule keeps (docs/model.md §10 (e)).
    assert theorem_scope(load_scenario(BUNDLED_DIR / f"{name}.toml")) is None


@pytest.mark.parametrize("changes", [
    {"right__z": [[0.1, 0.2], [0.3, 0.4]]},
    {"left__tool": {"polygon": [[0, -0.01], [0.05, 0], [0, 0.01]]}},
    {"left__tool": {"polygon": [[0, -0.01], [0.05, 0], [0, 0.01]], "z": [0.0, 0.1]}},
    {},
])
def test_tools_and_heights_carry_no_scope_label(changes):
    assert theorem_scope(factory.scenario(**changes)) is None
    assert theorem_scope(load_scenario(DATA / "tools-heights.toml")) is None


def test_a_feature_not_covered_would_be_named(monkeypatch):
    # The one rule still labels what the theorem would not cover: a planted feature (seeded).
    from cfmpa.spec import _scope
    assert SCOPE_CHECKED == ("checked on samples and by the certificate, not yet by the safety "
                             "theorem")
    monkeypatch.setattr(_scope, "NOT_COVERED", (
        ("tool", lambda s: any(a.tool is not None for a in (s.left, s.right))),
        ("heights", lambda s: any(a.z is not None for a in (s.left, s.right)))))
    both = theorem_scope(load_scenario(DATA / "tools-heights.toml"))
    assert both == f"tool and heights: {SCOPE_CHECKED}"
    assert theorem_scope(load_scenario(BUNDLED_DIR / "default.toml")) is None


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
