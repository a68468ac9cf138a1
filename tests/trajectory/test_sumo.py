"""SUMO drives: the fitted truth closes under an independent strapdown, has no gyro spikes, stands
still without heading noise, stays on SUMO's path, is placed on the Earth as the network says,
and carries the network's tunnels as zones. Networks: the shipped plain-XML and OSM ones, the
real OpenDRIVE roads and SUMO net of ../shared/refdata/roads/esmini, and netgenerate recipes."""

from __future__ import annotations

import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pymap3d
import pytest
import yaml

from estimators.toolbox.strapdown import run_strapdown
from simulator import earth
from simulator.dataset.generate import build_truth
from simulator.scenario import load_scenario
from simulator.sensors import resolve_block
from simulator.sensors.imu import Imu
from simulator.tables import as_frame
from simulator.trajectory.sumo import place_drive, run_sumo
from simulator.trajectory.sumo_network import prepare_network

REPO = Path(__file__).resolve().parents[2]
NETWORKS = REPO / "scenarios" / "networks"
ESMINI = Path(__file__).resolve().parents[3] / "shared" / "refdata" / "roads" / "esmini"
START = {"utc": "2024-05-01T08:00:00Z", "lat": 46.9480, "lon": 7.4474, "alt": 540.0}


def write_scenario(folder: Path, trajectory: dict, name: str = "drive") -> Path:
    """A SUMO scenario with a rigid body: these tests hold the fitted road itself (its path,
    grades, stops) against SUMO's and the networks' (the body on it: tests/vehicle/)."""
    path = folder / f"{name}.yaml"
    path.write_text(yaml.safe_dump({
        "name": name, "start": START, "trajectory": {"kind": "sumo", **trajectory},
        "vehicle": "rigid", "sensors": {"imu": {"preset": "ideal", "rate": 100}}}))
    return path


def sumo_inputs(scenario_path: Path):
    """The SUMO run behind a scenario (from the cache) and its positions in the fit's frame."""
    scenario = load_scenario(scenario_path)
    traj = scenario.data["trajectory"]
    network = prepare_network(traj["network"], scenario_path.parent)
    drive = run_sumo(traj, network)
    return scenario, drive, place_drive(drive.xyz, network, scenario.data["start"])


@pytest.fixture(scope="module")
def hilly_city(tmp_path_factory):
    """Ten minutes on the shipped hills network with a traffic light at every junction and 20
    other cars: stops, turns, 7.5 % grades, a tunnel and a bridge."""
    folder = tmp_path_factory.mktemp("hills")
    nodes = (NETWORKS / "hills.nod.xml").read_text().replace('type="priority"',
                                                              'type="traffic_light"')
    (folder / "lights.nod.xml").write_text(nodes)
    path = write_scenario(folder, {
        "network": {"nodes": "lights.nod.xml", "edges": str(NETWORKS / "hills.edg.xml")},
        "route": {"length": 20000}, "traffic": {"vehicles": 20}, "initial_stop": 20,
        "max_duration": 600, "seed": 4})
    scenario, drive, frame = sumo_inputs(path)
    return build_truth(scenario.data), drive, frame


def test_ten_minute_drive_has_stops_turns_and_slopes(hilly_city):
    truth, _, _ = hilly_city
    assert truth.duration_s == pytest.approx(620.0, abs=1.0)  # 20 s initial stop + 600 s
    table = truth.table()
    moving_again = table.t > 60.0
    assert (table.speed[moving_again] == 0.0).sum() > 100  # a stop at a light or in a queue
    assert np.degrees(np.ptp(np.unwrap(table.yaw))) > 180.0
    assert np.degrees(np.abs(table.pitch)).max() > 3.5  # the 7.5 % grades (4.3 deg)
    assert "tunnel" in set(table.zone)


def test_strapdown_closure_on_sumo_drive(hilly_city):
    """Issue 3: the ideal 100 Hz IMU (increments) integrated by the NED strapdown stays within
    2 m horizontally and 0.2 deg in yaw of the truth over the ten-minute drive. Measured: see
    the figures in the report (a few mm and 1e-6 deg)."""
    truth, _, _ = hilly_city
    imu = Imu(resolve_block("imu", {"preset": "ideal", "rate": 100.0, "output": "increment",
               "axes": ["gyro_x", "gyro_y", "gyro_z", "accel_x", "accel_y", "accel_z"]}))
    table = as_frame(imu.generate(truth, None)["imu"])
    t = np.concatenate([[0.0], table.t.to_numpy()])
    ref = truth.table(t)
    first = ref.iloc[0]
    q, _, pos = run_strapdown(
        earth.euler_to_quat(first.roll, first.pitch, first.yaw),
        first[["vn", "ve", "vd"]].to_numpy(float),
        np.array([np.radians(first.lat), np.radians(first.lon), first.alt]),
        table[["gyro_x", "gyro_y", "gyro_z"]].to_numpy(),
        table[["accel_x", "accel_y", "accel_z"]].to_numpy(), np.diff(t))
    rn, re = earth.radii_of_curvature(np.radians(ref.lat.to_numpy()))
    north = (pos[:, 0] - np.radians(ref.lat.to_numpy())) * (rn + ref.alt.to_numpy())
    east = (pos[:, 1] - np.radians(ref.lon.to_numpy())) * (re + ref.alt.to_numpy()) * np.cos(
        pos[:, 0])
    _, _, yaw = earth.quat_to_euler(q)
    assert np.max(np.hypot(north, east)) < 2.0
    assert np.max(np.abs(np.degrees(earth.wrap_angle(yaw - ref.yaw.to_numpy())))) < 0.2


def implied_yaw_rate(t: np.ndarray, enu: np.ndarray, chord: float = 2.0) -> np.ndarray:
    """|yaw rate| SUMO's own path implies: the curvature of the circle through the points
    ``chord`` metres behind and ahead (Menger curvature), times the speed from the positions."""
    step = np.linalg.norm(np.diff(enu[:, :2], axis=0), axis=1)
    s = np.concatenate([[0.0], np.cumsum(step)])
    speed = np.gradient(s, t)

    def at(q):
        return np.stack([np.interp(q, s, enu[:, 0]), np.interp(q, s, enu[:, 1])], axis=-1)

    a, b, c = at(s - chord), at(s), at(s + chord)
    cross = (b - a)[:, 0] * (c - b)[:, 1] - (b - a)[:, 1] * (c - b)[:, 0]
    sides = np.prod([np.linalg.norm(x, axis=1) for x in (b - a, c - b, a - c)], axis=0)
    return 2.0 * np.abs(cross) / np.maximum(sides, 1e-9) * speed


def test_no_yaw_rate_spikes(hilly_city):
    """The 99.9th percentile of |yaw rate| stays under the one SUMO's path and speed imply
    (2 m chords) plus a margin of 10 % + 0.05 rad/s."""
    truth, drive, frame = hilly_city
    wz = truth.table().wz.to_numpy()
    implied = implied_yaw_rate(drive.t, frame.enu)
    assert np.percentile(np.abs(wz), 99.9) < 1.1 * np.percentile(implied, 99.9) + 0.05


def test_standstill_yaw_rate_is_earth_rate(hilly_city):
    truth, _, _ = hilly_city
    table = truth.table()
    still = table[table.speed == 0.0]
    assert len(still) > 1000
    k = truth.inertial(still.t.to_numpy())
    c_bn = earth.euler_to_dcm(k["roll"], k["pitch"], k["yaw"])
    expected = np.einsum("nji,nj->ni", c_bn, earth.earth_rate_ned(k["lat"]))
    np.testing.assert_allclose(k["w_body"], expected, atol=1e-15)
    for start, end in _runs(table.speed.to_numpy() == 0.0, table.t.to_numpy()):
        stop = table[(table.t >= start) & (table.t <= end)]
        # no heading change while stopped: at a stop's last sample the fitted distance may
        # already differ by the rounding of its second differences (about 1e-7 m, fit.py),
        # worth curvature x 1e-7 m of heading (1e-10 rad on this drive since issue 13's SUMO
        # braking changed the run)
        assert np.ptp(stop.yaw) < 1e-9


def _runs(mask: np.ndarray, t: np.ndarray) -> list[tuple[float, float]]:
    edges = np.diff(np.concatenate([[0], mask.astype(int), [0]]))
    return list(zip(t[np.flatnonzero(edges == 1)], t[np.flatnonzero(edges == -1) - 1],
                    strict=True))


def test_fitted_path_stays_on_sumo_path(hilly_city):
    """Truth positions at SUMO's sample times against SUMO's positions, in the same local
    frame: 99 % within 0.5 m horizontally (0.41 m measured; 0.2 m held before SUMO's
    too-sharp turns were widened, which moved about 1 % of the samples, in those turns,
    further); heights within 0.1 m. All within the fit's
    ``min_radius`` (4.5 m): where SUMO turns tighter than a car can, the fit widens the turn
    and cuts its corner, by (R - r)(sqrt(2) - 1) in a right-angle turn widened from r to R and
    by up to R - r in a U-turn (2.2 m at worst on this drive; 0.5 m without the widening)."""
    truth, drive, frame = hilly_city
    k = truth.inertial(drive.t)
    ned = earth.ecef_to_ned(earth.geodetic_to_ecef(k["lat"], k["lon"], k["alt"]),
                            *frame.reference)
    # the frame's up is height above the reference, not the tangent plane's up
    horizontal = np.hypot(ned[:, 1] - frame.enu[:, 0], ned[:, 0] - frame.enu[:, 1])
    assert np.percentile(horizontal, 99) < 0.5
    assert horizontal.max() < 4.5
    assert np.max(np.abs(k["alt"] - frame.reference[2] - frame.enu[:, 2])) < 0.1


def test_tunnel_zone_covers_the_tunnel_edge(hilly_city):
    truth, _, _ = hilly_city
    tunnels = [z for z in truth.profile.zones if z[2] == "tunnel"]
    assert tunnels
    for start, end, _ in tunnels:
        travelled = truth.profile.distance_of_time(end) - truth.profile.distance_of_time(start)
        if end < truth.duration_s - 1:  # a tunnel the drive went through from end to end
            assert travelled == pytest.approx(1000.0, abs=30.0)


def test_plain_network_origin_is_placed_at_start(tmp_path):
    """A network without georeference has x = y = 0 at start.lat/lon: the truth starts where
    SUMO's first position is, east x and north y of start (checked with pymap3d)."""
    path = write_scenario(tmp_path, {
        "network": {"nodes": str(NETWORKS / "hills.nod.xml"),
                    "edges": str(NETWORKS / "hills.edg.xml")},
        "route": {"edges": ["valley", "climb"]}})
    scenario, drive, _ = sumo_inputs(path)
    truth = build_truth(scenario.data)
    x, y, z = drive.xyz[0]
    lat, lon, _ = pymap3d.enu2geodetic(x, y, 0.0, START["lat"], START["lon"], START["alt"])
    assert truth.origin.lat_deg == pytest.approx(lat, abs=1e-6)  # 0.1 m
    assert truth.origin.lon_deg == pytest.approx(lon, abs=1.5e-6)
    assert truth.origin.alt_m == pytest.approx(START["alt"] + z, abs=0.05)
    assert truth.origin.heading_deg == pytest.approx(90.0, abs=1.0)  # "valley" runs east


def test_osm_network_keeps_true_coordinates():
    """The shipped OSM drive stays within a lane of the OSM ways (node lat/lon read from the
    file, converted with pymap3d) and at the ways' ele + start.alt; its tunnel is a zone."""
    path = REPO / "scenarios" / "sumo_lakeside_osm.yaml"
    scenario = load_scenario(path)
    truth = build_truth(scenario.data)
    table = truth.table()
    root = ET.parse(NETWORKS / "lakeside.osm").getroot()
    nodes = {n.get("id"): (float(n.get("lat")), float(n.get("lon")),
                           float(n.find("tag[@k='ele']").get("v"))) for n in root.iter("node")}
    lat0, lon0 = table.lat.iloc[0], table.lon.iloc[0]
    ways = [[nodes[nd.get("ref")] for nd in w.iter("nd")] for w in root.iter("way")]
    e_t, n_t, _ = pymap3d.geodetic2enu(table.lat, table.lon, 0.0, lat0, lon0, 0.0)
    best = np.full(len(table), np.inf)
    best_ele = np.zeros(len(table))
    for way in ways:
        lat, lon, ele = (np.array(v) for v in zip(*way, strict=True))
        e, n, _ = pymap3d.geodetic2enu(lat, lon, 0.0, lat0, lon0, 0.0)
        for i in range(len(e) - 1):
            d, f = _to_segment(e_t, n_t, e[i], n[i], e[i + 1], n[i + 1])
            closer = d < best
            best[closer] = d[closer]
            best_ele[closer] = ele[i] + f[closer] * (ele[i + 1] - ele[i])
    away_from_junctions = best < 10.0
    assert np.mean(away_from_junctions) > 0.95
    assert np.percentile(best, 90) < 3.5  # a lane is 3.2 m; SUMO drives off the centre line
    alt = table.alt.to_numpy()[away_from_junctions]
    expected = scenario.data["start"]["alt"] + best_ele[away_from_junctions]
    assert np.median(np.abs(alt - expected)) < 0.5
    tunnels = [z for z in truth.profile.zones if z[2] == "tunnel"]
    assert len(tunnels) == 1
    start, end, _ = tunnels[0]
    travelled = truth.profile.distance_of_time(end) - truth.profile.distance_of_time(start)
    assert travelled == pytest.approx(500.0, abs=25.0)


def _to_segment(px, py, ax, ay, bx, by):
    dx, dy = bx - ax, by - ay
    f = np.clip(((px - ax) * dx + (py - ay) * dy) / (dx * dx + dy * dy), 0.0, 1.0)
    return np.hypot(px - ax - f * dx, py - ay - f * dy), f


@pytest.fixture
def esmini() -> Path:
    if not ESMINI.is_dir():
        pytest.skip(f"reference roads not available: {ESMINI} is absent")
    return ESMINI


def xodr_max_grade(path: Path, road_id: str) -> float:
    """Steepest grade of an OpenDRIVE road from its elevation polynomials
    (z = a + b ds + c ds^2 + d ds^3 per record, OpenDRIVE 1.6 section 8.4.1)."""
    road = next(r for r in ET.parse(path).getroot().iter("road") if r.get("id") == road_id)
    records = list(road.find("elevationProfile").iter("elevation"))
    ends = [float(e.get("s")) for e in records[1:]] + [float(road.get("length"))]
    grades = []
    for rec, end in zip(records, ends, strict=True):
        _, b, c, d = (float(rec.get(k)) for k in "abcd")
        ds = np.linspace(0.0, end - float(rec.get("s")), 400)
        grades.append(b + 2 * c * ds + 3 * d * ds**2)
    return float(np.max(np.abs(np.concatenate(grades))))


def test_opendrive_tunnels_and_grade(esmini, tmp_path):
    """tunnels.xodr road 1: tunnels at s = 30 (250 m), 340 (8 m) and 400 m (150 m); the zones
    cover those stretches, and the steepest grade is the one of the road's elevation
    polynomials (16.2 %)."""
    path = write_scenario(tmp_path, {"network": str(esmini / "tunnels.xodr"),
                                     "route": {"edges": ["-1.0.00", "-1.160.19"]}})
    truth = build_truth(load_scenario(path).data)
    d = truth.profile.distance_of_time
    spans = sorted((float(d(a)), float(d(b))) for a, b, name in truth.profile.zones
                   if name == "tunnel")
    assert len(spans) == 3
    lengths = [b - a for a, b in spans]
    # lane lengths differ from the reference line by up to 2 % (3-D length, lane offset)
    assert lengths[0] == pytest.approx(250.0, rel=0.04)
    assert lengths[1] == pytest.approx(8.0, abs=2.0)
    assert lengths[2] == pytest.approx(150.0, rel=0.04)
    assert spans[2][0] - spans[0][0] == pytest.approx(370.0, rel=0.04)
    grade = np.abs(np.tan(truth.table().pitch))
    assert grade.max() == pytest.approx(xodr_max_grade(esmini / "tunnels.xodr", "1"), abs=0.005)


def test_opendrive_steep_road(esmini, tmp_path):
    """tunnels.xodr road 2 climbs 20 m and back down in 300 m with grades up to 30 %."""
    path = write_scenario(tmp_path, {"network": str(esmini / "tunnels.xodr"),
                                     "route": {"edges": ["-2.0.00"]}})
    table = build_truth(load_scenario(path).data).table()
    steepest = xodr_max_grade(esmini / "tunnels.xodr", "2")
    assert np.abs(np.tan(table.pitch)).max() == pytest.approx(steepest, abs=0.01)
    assert np.ptp(table.alt) == pytest.approx(20.0, abs=0.3)


def test_existing_net_xml(esmini, tmp_path):
    """e6mini.net.xml (SUMO net with 3-D lane shapes, z -3.1 ... 2.4 m, grades up to 2.9 %)."""
    path = write_scenario(tmp_path, {"network": str(esmini / "e6mini.net.xml"),
                                     "route": {"edges": ["0.0.00"]}})
    table = build_truth(load_scenario(path).data).table()
    assert np.abs(np.tan(table.pitch)).max() == pytest.approx(0.029, abs=0.004)
    assert 4.0 < np.ptp(table.alt) < 5.6
    assert table.distance.iloc[-1] > 1000.0


@pytest.mark.parametrize("recipe", [{"type": "spider", "arms": 5, "circles": 2},
                                    {"type": "random", "iterations": 30}])
def test_netgenerate_recipes(tmp_path, recipe):
    path = write_scenario(tmp_path, {"network": {"netgenerate": recipe},
                                     "route": {"length": 800}, "traffic": {"vehicles": 3}})
    truth = build_truth(load_scenario(path).data)
    assert truth.table().distance.iloc[-1] > 700.0


def test_zone_tags_of_network_edges(tmp_path):
    """Every way an edge can be marked: a zone parameter, OSM tunnel/covered tags, an edge type;
    junction-internal edges and untagged edges are no zone; the projection is read."""
    net = tmp_path / "tags.net.xml"
    net.write_text(
        '<net><location netOffset="-10.00,-20.00" projParameter="+proj=utm +zone=32 '
        '+ellps=WGS84"/>'
        '<edge id="a"><param key="zone" value="garage"/></edge>'
        '<edge id="b"><param key="tunnel" value="building_passage"/></edge>'
        '<edge id="c"><param key="covered" value="yes"/></edge>'
        '<edge id="d" type="highway.parking_garage"/>'
        '<edge id="e" type="highway.primary"><param key="bridge" value="yes"/></edge>'
        '<edge id=":j_0" function="internal"><param key="zone" value="garage"/></edge></net>')
    network = prepare_network(str(net), tmp_path)
    assert network.zones == {"a": [(0.0, 1.0, "garage")], "b": [(0.0, 1.0, "tunnel")],
                             "c": [(0.0, 1.0, "underpass")], "d": [(0.0, 1.0, "garage")]}
    assert network.georeferenced
    lon, lat = network.to_lonlat(np.array([[500000.0 - 10.0, -20.0]]))  # x, y minus netOffset
    assert lon[0] == pytest.approx(9.0) and lat[0] == pytest.approx(0.0, abs=1e-9)


def test_same_scenario_gives_identical_truth_without_cache(tmp_path, monkeypatch):
    """SUMO is seeded by trajectory.seed: two generations from empty caches write byte-identical
    truth files (SPEC section 2)."""
    from simulator.cli import main

    scenario = REPO / "scenarios" / "sumo_lakeside_osm.yaml"
    for run in ("a", "b"):
        monkeypatch.setenv("LANDNAV_CACHE", str(tmp_path / f"cache-{run}"))
        assert main(["generate", str(scenario), "-o", str(tmp_path / run)]) == 0
    assert (tmp_path / "a" / "truth.parquet").read_bytes() == (
        tmp_path / "b" / "truth.parquet").read_bytes()
    assert any((tmp_path / "cache-a" / "sumo").glob("run-*.npz"))


def test_city_grid_lights_give_time_to_stop_comfortably():
    """The shipped city grid's yellow lights last ITE's change interval for the ego's 2 m/s^2,
    1 s + 13.89 / (2 x 2) = 4.47 s, rounded up to netgenerate's whole 5 s (its own default was
    3 s), and the drive's hardest braking after the fit is the ego's comfortable braking, not
    SUMO's emergency stop at a light turned red 1.3 m ahead (-11.6 m/s^2 with the 3 s yellow,
    docs/vehicle.md): measured -2.87 m/s^2."""
    from simulator.trajectory.sumo_network import yellow_time

    assert yellow_time(13.89, 2.0) == pytest.approx(1.0 + 13.89 / 4.0)
    scenario = load_scenario(REPO / "scenarios" / "sumo_city_grid.yaml")
    traj = scenario.data["trajectory"]
    network = prepare_network(traj["network"], REPO / "scenarios", traj["ego"]["decel"])
    phases = ET.parse(network.path).getroot().iter("phase")
    yellow = {float(p.get("duration")) for p in phases if "y" in p.get("state")}
    assert yellow == {5.0}
    profile = scenario.drive.profile
    t = np.arange(0.0, profile.duration_s, 0.01)
    assert profile.distance_of_time.evaluate(t, (2,))[0].min() > -3.0
