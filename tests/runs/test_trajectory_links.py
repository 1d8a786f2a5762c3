"""Links named as docs/model.md §2 names them (1-based, with words) in certify's and monitor's
messages and JSON, plan.json's certificate and the certificate's violation: a contact of the
forearms is link 2 and link 2, "forearm"."""

from __future__ import annotations

import json

import numpy as np
import pytest

import factory
from cfmpa.cli import main
from cfmpa.errors import CertificateViolation
from cfmpa.spec import (
    Trajectory,
    certificate_json,
    certify_trajectory,
    closest_links,
    link_name,
    load_trajectory,
    require_clear,
    tolerance_rad,
    trajectory_csv,
)
from cfmpa.spec._kinematics import LINK_WORDS

HEADER = "t,left1,left2,right1,right2\n"
H = np.pi / 2
# Both upper arms upright (0.6 m apart); the left forearm points at the right arm, the right
# forearm swings from upright towards the left one: only the forearms can meet.
LEFT = [H, -H]
SWING = Trajectory(np.array([0.0, 2.0]), np.array([LEFT + [H, 0.0], LEFT + [H, H]]))
FOREARMS = "left link 2 (forearm) and right link 2 (forearm)"


@pytest.fixture(scope="module")
def cell(tmp_path_factory):
    doc = factory.doc(right__start_cell=[2, 8], right__goal_cell=[13, 5])
    s, scen, folder, p = factory.planned(tmp_path_factory.mktemp("links"), doc)
    return s, scen, folder / "traj.csv", tolerance_rad(s, p.certificate)


def test_link_name_is_one_based_with_words():
    assert link_name("left", 2) == "left link 2 (forearm)"
    assert link_name("right", 1) == "right link 1 (upper arm)"
    assert LINK_WORDS == {1: "upper arm", 2: "forearm"}
    assert link_name("right", 3) == "right tool"      # part 3: the tool (docs/model.md §2)
    for bad in (("left", 0), ("right", 4), ("middle", 1)):
        with pytest.raises(ValueError, match=f"no part {bad[1]} of arm '{bad[0]}'"):
            link_name(*bad)
    d = np.full((2, 2), 1.0)
    d[1, 1] = 0.0                                     # array index (1, 1): the forearms
    assert closest_links(d) == (2, 2)
    d[1, 1], d[0, 1] = 1.0, 0.0
    assert closest_links(d) == (1, 2)


def test_a_forearm_contact_is_link_2_and_2_in_the_certificate(cell):
    s = cell[0]
    cert = certify_trajectory(s, SWING)
    assert not cert.clear and cert.contact is not None
    assert cert.contact[1] == (2, 2) and cert.contact_detail.links == (2, 2)
    js = certificate_json(cert)["contact"]
    assert js["links"] == [2, 2] and js["links_text"] == FOREARMS
    with pytest.raises(CertificateViolation) as e:
        require_clear(cert)
    assert FOREARMS in str(e.value) and "link 1" not in str(e.value)


def test_certify_names_the_forearms(cell, tmp_path, capsys):
    _, scen, _, _ = cell
    f = tmp_path / "swing.csv"
    f.write_text(trajectory_csv(SWING))
    assert main(["certify", str(scen), "--traj", str(f), "--json", str(tmp_path / "c.json")]) == 1
    c = json.loads((tmp_path / "c.json").read_text())["contact"]
    assert c["links"] == [2, 2] and c["links_text"] == FOREARMS
    out = capsys.readouterr().out
    assert FOREARMS in out and "link 1" not in out


def test_monitor_names_the_forearms_of_a_sample_in_contact(cell, tmp_path, capsys):
    s, scen, traj_csv, tol = cell
    traj = load_trajectory(traj_csv, s)
    t_end = float(traj.t[-1])
    log = tmp_path / "log.csv"
    rows = [[float(t), *traj.at(t)] for t in np.linspace(traj.t[0], t_end, 2001)]
    rows[1000][1:] = LEFT + [H, float(SWING.at(1.9)[3])]       # the forearms overlap here
    log.write_text(HEADER + "".join(",".join(repr(float(x)) for x in r) + "\n" for r in rows))
    assert main(["monitor", str(scen), "--traj", str(traj_csv), "--log", str(log), "--json",
                 str(tmp_path / "m.json")]) == 1
    doc = json.loads((tmp_path / "m.json").read_text())
    c = doc["contact"]
    assert c["in_contact"] is True and c["links"] == [2, 2] and c["links_text"] == FOREARMS
    assert f"IN CONTACT ({FOREARMS})" in capsys.readouterr().out   # with the verdict
