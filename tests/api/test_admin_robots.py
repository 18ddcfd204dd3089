"""Instructor admin API for the robots on the bench (the inventory)."""

from __future__ import annotations


def test_register_list_take_out_of_service_and_remove(lab):
    admin = lab.admin()
    made = admin.post(
        "/api/admin/robots", json={"name": "crowbot-1", "kind": "crowbot", "address": "10.0.0.7"}
    )
    assert made.status_code == 201, made.text
    robot = made.json()
    assert robot["transport"] == "rosserial" and robot["connection"] == "not connected"
    assert robot["limits"]["max_linear_m_s"] > 0 and robot["watchdog_s"] == 0.5
    again = admin.post(
        "/api/admin/robots", json={"name": "crowbot-1", "kind": "crowbot", "address": "10.0.0.8"}
    )
    assert again.status_code == 409 and "registered already" in again.json()["detail"]
    names = [r["name"] for r in admin.get("/api/admin/robots").json()["robots"]]
    assert "crowbot-1" in names
    out = admin.patch("/api/admin/robots/crowbot-1", json={"in_service": False})
    assert out.json()["in_service"] is False
    assert admin.delete("/api/admin/robots/crowbot-1").json() == {"ok": True}
    missing = admin.delete("/api/admin/robots/crowbot-1")
    assert missing.status_code == 404 and "no robot named" in missing.json()["detail"]


def test_bad_robot_entries_are_sentences(lab):
    admin = lab.admin()
    create = admin.post(
        "/api/admin/robots", json={"name": "roomba-1", "kind": "turtlebot", "address": "/dev/x"}
    )
    assert create.status_code == 422 and "baud" in create.json()["detail"]
    for body in (
        {"name": "Bad Name", "kind": "crowbot", "address": "1.2.3.4"},
        {"name": "ok", "kind": "drone", "address": "1.2.3.4"},
        {"name": "ok", "kind": "crowbot", "address": "1.2.3.4", "watchdog_s": 0},
        {"name": "ok", "kind": "crowbot", "address": "x\u0000"},
        {"name": "ok", "kind": "crowbot", "address": "1.2.3.4",
         "limits": {"max_linear_m_s": -1, "max_angular_rad_s": 1, "max_linear_accel_m_s2": 1,
                    "max_angular_accel_rad_s2": 1}},
    ):  # fmt: skip
        answer = admin.post("/api/admin/robots", json=body)
        assert answer.status_code == 422, (body, answer.text)


def test_students_cannot_see_the_inventory(lab):
    student = lab.student("curious")
    assert student.get("/api/admin/robots").status_code == 404
    valid = {"name": "sneaky", "kind": "crowbot", "address": "10.9.9.9"}
    assert student.post("/api/admin/robots", json=valid).status_code == 404
    assert "sneaky" not in [
        r["name"] for r in lab.admin().get("/api/admin/robots").json()["robots"]
    ]
