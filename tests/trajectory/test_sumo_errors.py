"""Bad SUMO input ends in one clear message naming the file and the key, exit code 2, no
traceback, and no dataset folder."""

from __future__ import annotations

from pathlib import Path

import pytest
import yaml

from simulator.cli import main
from simulator.trajectory import sumo as sumo_source

NETWORKS = Path(__file__).resolve().parents[2] / "scenarios" / "networks"
HILLS = {"nodes": str(NETWORKS / "hills.nod.xml"), "edges": str(NETWORKS / "hills.edg.xml")}


def _scenario(tmp_path: Path, network, route) -> Path:
    path = tmp_path / "bad.yaml"
    path.write_text(yaml.safe_dump({
        "start": {"lat": 46.9, "lon": 7.4, "alt": 500.0},
        "trajectory": {"kind": "sumo", "network": network, "route": route}}))
    return path


def _fails(path: Path, capsys, tmp_path: Path) -> str:
    """Run validate and generate; both must exit 2 with the problem on stderr, nothing else."""
    assert main(["validate", str(path)]) == 2
    out = tmp_path / "never"
    assert main(["generate", str(path), "-o", str(out)]) == 2
    assert not out.exists()
    err = capsys.readouterr().err
    assert "Traceback" not in err
    assert str(path) in err
    return err


def test_missing_network_file(tmp_path, capsys):
    err = _fails(_scenario(tmp_path, "nowhere.net.xml", {"length": 500}), capsys, tmp_path)
    assert "trajectory.network: network file not found" in err
    assert "nowhere.net.xml" in err


def test_missing_plain_xml_file(tmp_path, capsys):
    network = {"nodes": HILLS["nodes"], "edges": "missing.edg.xml"}
    err = _fails(_scenario(tmp_path, network, {"length": 500}), capsys, tmp_path)
    assert "trajectory.network.edges: network file not found" in err


def test_unconnected_edges(tmp_path, capsys):
    err = _fails(_scenario(tmp_path, HILLS, {"edges": ["valley", "tunnel"]}), capsys, tmp_path)
    assert "trajectory.route.edges.1: edge 'tunnel' does not follow edge 'valley'" in err


def test_unknown_edge(tmp_path, capsys):
    err = _fails(_scenario(tmp_path, HILLS, {"from": "valley", "to": "tunel"}), capsys,
                 tmp_path)
    assert "trajectory.route.to: edge 'tunel' does not exist in the network" in err
    assert "did you mean" in err and "tunnel" in err


def test_corrupt_network_is_a_sumo_error(tmp_path, capsys):
    net = tmp_path / "broken.net.xml"
    net.write_text('<net version="1.20"><edge id="a" from="x" to="y"><lane id="a_0" '
                   'length="10" shape="0,0 10,0"/></edge></net>')
    err = _fails(_scenario(tmp_path, str(net), {"length": 500}), capsys, tmp_path)
    assert "trajectory.network: SUMO cannot load the network" in err


def test_netconvert_error(tmp_path, capsys):
    nodes = tmp_path / "n.nod.xml"
    nodes.write_text('<nodes><node id="a" x="0" y="0"/></nodes>')
    edges = tmp_path / "e.edg.xml"
    edges.write_text('<edges><edge id="e" from="a" to="nowhere"/></edges>')
    err = _fails(_scenario(tmp_path, {"nodes": str(nodes), "edges": str(edges)},
                           {"length": 500}), capsys, tmp_path)
    assert "trajectory.network: netconvert failed" in err


def test_two_route_forms(tmp_path, capsys):
    err = _fails(_scenario(tmp_path, HILLS, {"edges": ["valley"], "length": 500}), capsys,
                 tmp_path)
    assert "trajectory.route: give exactly one route form" in err


def test_libsumo_is_not_reentrant():
    """libsumo holds one simulation per process: a second start while one runs is refused."""
    assert sumo_source._SUMO_LOCK.acquire(blocking=False)
    try:
        with pytest.raises(RuntimeError, match="already running"):
            sumo_source._simulate({}, None)
    finally:
        sumo_source._SUMO_LOCK.release()


def test_a_sumo_drive_without_sumo_says_what_to_install(tmp_path, capsys, monkeypatch):
    """SUMO is an optional part (``pip install -e '.[sumo]'``): without it, a SUMO scenario is
    refused with what to install, naming the file and the trajectory."""
    monkeypatch.setattr(sumo_source, "SUMO_PACKAGES", ("sumo", "landnav_no_such_package"))
    err = _fails(_scenario(tmp_path, HILLS, {"length": 500}), capsys, tmp_path)
    assert "trajectory: a SUMO drive needs SUMO" in err
    assert "landnav_no_such_package not installed" in err and "pip install -e '.[sumo]'" in err
