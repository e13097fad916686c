"""The teach page without a browser: its session (follow a target, branches, collisions, readings against
Pinocchio), the recorder that feeds the page, and the server's answers to good and bad requests."""

import json
import socket
import struct
import time
import urllib.error
import urllib.request

import meshcat
import meshcat.geometry as g
import numpy as np
import pinocchio as pin
import pytest
import umsgpack
from helpers import pinocchio_tool

import kinelab
from kinelab.collision import Collisions, Environment, Obstacle, collision_model
from kinelab.errors import ConfigurationError, KinelabError, TargetError
from kinelab.view.teach import TeachOptions, TeachServer, TeachSession, teach
from kinelab.view.teach.recorder import RecordingWindow

TOL = 1e-6
FLOOR_AND_TABLE = Environment((Obstacle("plane", name="floor"),
                               Obstacle("box", size=(0.6, 0.8, 0.05), xyz=(0.5, 0.0, 0.2), name="table")))


def meets(robot, q, target, tol=TOL):
    oMtool = pinocchio_tool(robot, q)
    inside = np.all(q >= robot.lower - 1e-12) and np.all(q <= robot.upper + 1e-12)
    return (np.linalg.norm(oMtool.translation - target.translation) <= tol
            and np.linalg.norm(pin.log3(oMtool.rotation.T @ target.rotation)) <= tol and inside)


def drawn(session, path):
    """The last transform the session gave a scene node (4 × 4, parent frame), read from the recorded commands."""
    for packed in reversed(session.window.since(0)[1]):
        cmd = umsgpack.unpackb(packed)
        if cmd["type"] == "set_transform" and cmd["path"] == path:
            return np.array(cmd["matrix"], dtype=float).reshape(4, 4).T  # meshcat sends columns first
    raise AssertionError(f"no transform of {path}")


def objects(session, prefix):
    """The scene nodes under ``prefix`` that hold an object now (the recorder keeps what a fresh page would get)."""
    return {c["path"] for c in map(umsgpack.unpackb, session.window.since(0)[1])
            if c["type"] == "set_object" and c["path"].startswith(prefix)}


@pytest.fixture(scope="module")
def ur5():
    return kinelab.load("ur5")


def test_the_recorder_keeps_the_latest_command_per_node_and_what_came_after_a_number():
    window = RecordingWindow()
    vis = meshcat.Visualizer(window=window)
    vis["a"].set_object(g.Box([1, 1, 1]))
    vis["a"].set_transform(np.eye(4))
    seen = window.seq
    moved = np.eye(4)
    moved[0, 3] = 2.0
    vis["a"].set_transform(moved)
    vis["a"]["b"].set_object(g.Sphere(1.0))
    assert window.seq == 4
    fresh = [umsgpack.unpackb(p) for p in window.since(seen)[1]]
    assert [(c["type"], c["path"]) for c in fresh] == [("set_transform", "/meshcat/a"), ("set_object", "/meshcat/a/b")]
    assert fresh[0]["matrix"][12] == 2.0  # the later transform replaced the earlier one
    assert len(window.since(0)[1]) == 3
    vis["a"].delete()
    assert [umsgpack.unpackb(p)["type"] for p in window.since(0)[1]] == ["delete"]  # the node and all under it gone


def test_a_moved_target_is_followed_and_met_by_pinocchio_within_the_limits(ur5):
    rng = np.random.default_rng(4)
    session = TeachSession(ur5, [0.3, -1.2, 1.4, -0.8, 1.2, 0.2])
    for _ in range(25):
        step = pin.exp6(np.concatenate([rng.normal(0, 0.02, 3), rng.normal(0, 0.05, 3)]))
        before = session.q.copy()
        session.set_target(session.target * step)
        assert session.status.startswith("following"), session.status
        assert meets(ur5, session.q, session.target)
        assert np.abs(session.q - before).max() < 1.0  # followed from where it stood, not a jump to another branch
        tool = drawn(session, "/meshcat/frames/tool")
        assert np.abs(tool - pinocchio_tool(ur5, session.q).homogeneous).max() < 1e-9


def test_an_unreachable_target_keeps_q_and_says_so(ur5):
    session = TeachSession(ur5, [0.3, -1.2, 1.4, -0.8, 1.2, 0.2])
    before = session.q.copy()
    session.set_target(pin.SE3(np.eye(3), np.array([5.0, 0.0, 0.0])))
    assert session.status.startswith("not reached (unreachable)"), session.status
    assert np.array_equal(session.q, before)
    reading = session.readout()
    assert reading["position_error_m"] > 4.0 and reading["target"]["position_m"] == [5.0, 0.0, 0.0]


def test_bad_values_are_refused_by_name_and_change_nothing(ur5):
    session = TeachSession(ur5)
    q = session.q.copy()
    with pytest.raises(ConfigurationError, match="outside its limits"):
        session.set_q([9.0] * 6)
    with pytest.raises(ConfigurationError):
        session.set_q([0.1] * 5)
    with pytest.raises(TargetError, match="not a rotation"):
        session.set_target(pin.SE3(2 * np.eye(3), np.zeros(3)))
    with pytest.raises(TargetError, match="pinocchio.SE3"):
        session.set_target(np.eye(4))
    assert np.array_equal(session.q, q)
    with pytest.raises(ConfigurationError, match="outside its limits"):
        TeachSession(ur5, [9.0] * 6)


def test_stepping_through_branches_visits_each_once_and_each_meets_the_target(ur5):
    session = TeachSession(ur5, [0.3, -1.2, 1.4, -0.8, 1.2, 0.2])
    target = session.target
    seen = []
    for _ in range(12):
        session.step_branch()
        if seen and np.abs(session.q - seen[0]).max() < 1e-9:
            break
        seen.append(session.q.copy())
        assert meets(ur5, session.q, target)
    assert len(seen) >= 4 and session.readout()["branches"] == len(seen)  # the UR5 has up to 8
    assert np.abs(seen[0] - np.array([0.3, -1.2, 1.4, -0.8, 1.2, 0.2])).max() < 1e-6  # the first: where it stood
    gaps = [np.abs(a - b).max() for i, a in enumerate(seen) for b in seen[i + 1:]]
    assert min(gaps) > 1e-3
    session.step_branch(-1)
    assert np.abs(session.q - seen[-1]).max() < 1e-12  # back one


def test_with_collisions_on_every_branch_offered_is_clear_and_contacts_are_listed(ur5):
    model = collision_model(ur5, Collisions(environment=FLOOR_AND_TABLE))
    rng = np.random.default_rng(13)
    tried = 0
    for _ in range(40):
        q = ur5.random_q(rng)
        every = kinelab.solve_all(ur5, ur5.fk(q))
        clear = [b.q for b in every if model.contact(b.q, first_test=False) is None]
        if len(clear) in (0, len(every)):
            continue
        session = TeachSession(ur5, clear[0], TeachOptions(collisions=Collisions(environment=FLOOR_AND_TABLE)))
        session.set_collisions(True)
        offered = []
        for _ in range(len(every) + 1):
            session.step_branch()
            offered.append(session.q.copy())
            assert model.contact(session.q, first_test=False) is None and session.readout()["contacts"] == []
        assert session.readout()["branches"] == len(clear)
        tried += 1
        if tried == 3:
            break
    assert tried == 3
    inside = np.array([0.0, -0.9, 2.2, 0.0, 0.0, 0.0])  # the forearm down through the table
    session.set_q(inside)
    named = session.readout()["contacts"]
    assert named and named == [str(c) for c in model.contacts(inside)]
    assert {"/meshcat/obstacles/0", "/meshcat/obstacles/1"} <= objects(session, "/meshcat/obstacles/")
    red = objects(session, "/meshcat/contacts/")  # the links in contact drawn red: one node per collision object
    in_contact = {n for c in model.contacts(inside) for n in (c.first, c.second)}
    robot_names = {o.name for o in model.geom.geometryObjects if o.parentJoint != 0} & in_contact
    assert len(red) == len(robot_names) > 0
    session.set_collisions(False)
    assert session.readout()["contacts"] == [] and objects(session, "/meshcat/contacts/") == set()


def test_readings_and_the_ellipsoid_agree_with_pinocchio_s_jacobian(ur5):
    q = np.array([0.3, -1.2, 1.4, -0.8, 1.2, 0.2])
    session = TeachSession(ur5, q)
    data = ur5.model.createData()
    J = pin.computeFrameJacobian(ur5.model, data, ur5.to_pin_q(q), ur5.tool_frame_id, pin.LOCAL_WORLD_ALIGNED)
    U, s, _ = np.linalg.svd(J[:3])
    L = ur5.characteristic_length()
    scaled = np.linalg.svd(np.vstack([J[:3] / L, J[3:]]), compute_uv=False)
    reading = session.readout()
    assert reading["sigma_min"] == pytest.approx(scaled[-1], rel=1e-9)
    assert reading["manipulability"] == pytest.approx(np.prod(scaled), rel=1e-9)
    assert np.allclose(reading["ellipsoid_radii_m_per_rad"], s, rtol=1e-9)
    T = drawn(session, "/meshcat/ellipsoid")
    assert np.allclose(T[:3, 3], pinocchio_tool(ur5, q).translation, atol=1e-12)
    radii = np.linalg.norm(T[:3, :3], axis=0)
    assert np.allclose(radii, session.scale * s, rtol=1e-9)
    assert np.allclose(np.abs(np.sum(T[:3, :3] / radii * U, axis=0)), 1.0, atol=1e-9)  # its axes: J_v's directions
    assert max(radii) == pytest.approx(0.8 * session.scene.frame_length)  # the scale fixed at the start


def post(url, action, body):
    request = urllib.request.Request(url + action, data=body if isinstance(body, bytes) else json.dumps(body).encode(),
                                     method="POST", headers={"Content-Type": "application/json"})
    try:
        with urllib.request.urlopen(request, timeout=30) as reply:
            return reply.status, json.load(reply)
    except urllib.error.HTTPError as refused:
        return refused.code, json.load(refused)


def test_the_server_answers_on_loopback_and_refuses_bad_requests_by_name(ur5, capsys):
    with teach(ur5, q=[0.3, -1.2, 1.4, -0.8, 1.2, 0.2]) as page:
        assert page.server.httpd.server_address[0] == "127.0.0.1" and page.url.startswith("http://127.0.0.1:")
        with urllib.request.urlopen(page.url, timeout=30) as reply:
            text = reply.read().decode("utf-8")
        assert "<title>ur5 · teach — kinelab</title>" in text
        assert f'src="{page.url}"' in page._repr_html_()
        with urllib.request.urlopen(page.url + "state?since=0", timeout=30) as reply:
            first = json.load(reply)
        assert first["seq"] > 0 and len(first["commands"]) > 10 and first["readout"]["robot"] == "ur5"
        code, moved = post(page.url, "q", {"q": [0.4, -1.2, 1.4, -0.8, 1.2, 0.2], "since": first["seq"]})
        assert code == 200 and moved["readout"]["q"][0] == 0.4 and 0 < len(moved["commands"]) < 20
        for action, body, words in (("q", {"q": [0.1] * 5}, "6"), ("q", {"q": [9.0] * 6}, "outside its limits"),
                                    ("target", {"matrix": [1.0] * 12 + [0, 0, 0, 1]}, "not a rotation"),
                                    ("target", {"matrix": [float("nan")] * 16}, "not finite"),
                                    ("target", {"matrix": "x"}, "16 numbers"), ("fly", {}, "unknown action"),
                                    ("target", {"matrix": [*np.eye(4)[:3].ravel(), 5, 5, 5, 5]}, "last row"),
                                    ("branch", {"step": 2}, "1 (next) or -1"),
                                    ("collisions", {"on": "yes"}, "true or false"),
                                    ("q", b"not json", "not a JSON object")):
            code, reply = post(page.url, action, body)
            assert code == 400 and words in reply["error"], (action, reply)
        assert page.session.q[0] == 0.4  # nothing refused changed it
        host, port = page.server.httpd.server_address
        for _ in range(3):  # a browser that goes away while the scene is sent (a reload): nothing printed
            with socket.create_connection((host, port)) as gone:
                gone.setsockopt(socket.SOL_SOCKET, socket.SO_LINGER, struct.pack("ii", 1, 0))  # close with a reset
                gone.sendall(b"GET /state?since=0 HTTP/1.1\r\nHost: x\r\n\r\n")
                gone.recv(1)
        time.sleep(0.5)
        assert "Traceback" not in capsys.readouterr().err
        with socket.socket() as other, pytest.raises(KinelabError, match="give another --port"):
            other.bind(("127.0.0.1", 0))
            other.listen()
            TeachServer(page.session, other.getsockname()[1])
