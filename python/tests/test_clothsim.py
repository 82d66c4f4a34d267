"""The clothsim Python module (docs/python.md) against the program and against physics.

Run by ctest (Python.Pytest) with PYTHONPATH at the built module, CLOTHSIM_SOURCE_DIR and
CLOTHSIM_BINARY set.
"""
import json
import os
import subprocess
import sys

import numpy as np
import pytest

import clothsim

SRC = os.environ.get("CLOTHSIM_SOURCE_DIR", os.path.join(os.path.dirname(__file__), "..", ".."))
BINARY = os.environ.get("CLOTHSIM_BINARY", os.path.join(SRC, "build", "release", "clothsim"))
SCENES = os.path.join(SRC, "scenes")

# A 0.2 m cotton square, corners pinned along one edge, falling under gravity: no contact.
HANGING = {
    "name": "hanging",
    "analysis": "dynamic",
    "mesh": {"primitive": "grid", "size": [0.2, 0.2], "divisions": [6, 6]},
    "material": {"preset": "cotton"},
    "boundary": [{"select": {"box": [[-1, 0.099, -1], [1, 1, 1]]}, "fix": ["x", "y", "z"]}],
    "loads": {"gravity": [0, -9.81, 0]},
    "time": {"dt": 0.005, "end": 0.05, "output_fps": 100},
}


def test_steps_match_the_programs_run(tmp_path):
    """The same scene stepped here and run by the program: the same positions, to the bit."""
    sim = clothsim.Simulation(os.path.join(SCENES, "sleeve_twist.json"), set=["time.end=0.02", "time.output_fps=100"])
    assert sim.num_steps == round(0.02 / sim.dt)
    stats = sim.step(sim.num_steps)
    assert stats["step"] == sim.num_steps and sim.time == pytest.approx(0.02)
    out = tmp_path / "out"
    code = subprocess.run([BINARY, os.path.join(SCENES, "sleeve_twist.json"), "--no-render", "--out", str(out),
                           "--set", "time.end=0.02", "--set", "time.output_fps=100", "--set", "output.obj=true"],
                          capture_output=True, text=True)
    assert code.returncode == 0, code.stderr
    frames = sorted((out / "sleeve_twist" / "frames").glob("mesh_*.obj"))
    last = np.array([[float(x) for x in line.split()[1:4]] for line in open(frames[-1]) if line.startswith("v ")])
    # output.obj_level 0: the frames hold the limit points of the control vertices.
    assert np.array_equal(sim.surface_points, last)


def test_arrays_and_energy_balance():
    sim = clothsim.Simulation(HANGING)
    x0 = sim.positions
    assert x0.shape == (49, 3) and x0.dtype == np.float64
    assert sim.triangles.shape == (72, 3)
    assert np.all(sim.velocities == 0)
    assert sim.vertex_mass.sum() == pytest.approx(0.2 * 0.2 * 0.1238, rel=1e-12)  # cotton: 0.1238 kg/m^2
    sim.run()
    assert sim.time == pytest.approx(0.05)
    x = sim.positions
    pinned = x0[:, 1] >= 0.099
    assert np.array_equal(x[pinned], x0[pinned])
    assert x[~pinned, 1].mean() < x0[~pinned, 1].mean()  # it falls
    e = sim.energies()
    # The loads' work went into kinetic and elastic energy, or was damped away: never more.
    assert e["kinetic"] > 0 and e["elastic"] > 0
    assert e["kinetic"] + e["elastic"] <= e["external_work"] + e["boundary_work"] + 1e-12
    c = sim.contact()
    assert c["enabled"] is False and c["active_pairs"] == 0
    # Positions are copies: changing one changes nothing in the simulation.
    x[:] = 0
    assert not np.all(sim.positions == 0)


def test_render_is_the_programs_picture_and_deterministic():
    sim = clothsim.Simulation(HANGING)
    sim.step(2)
    a = sim.render(width=160, height=120)
    b = sim.render(width=160, height=120)
    assert a.shape == (120, 160, 3) and a.dtype == np.uint8
    assert np.array_equal(a, b)
    assert (a != 255).any(axis=2).mean() > 0.05  # the cloth covers part of the white frame


def test_contact_scene_reports_contact():
    sim = clothsim.Simulation(os.path.join(SCENES, "sheet_on_sphere.json"), set=["time.end=0.3"])
    sim.run()
    c = sim.contact()
    assert c["enabled"] is True and c["active_pairs"] > 0 and c["energy"] > 0


def test_run_writes_the_usual_outputs(tmp_path):
    code = clothsim.run(os.path.join(SCENES, "sleeve_twist.json"), out=str(tmp_path), set=["time.end=0.02"],
                        render=False)
    assert code == 0
    summary = json.loads((tmp_path / "sleeve_twist" / "summary.json").read_text())
    assert summary["status"] == "completed"


def test_bad_input_raises_naming_the_key():
    with pytest.raises(ValueError, match="material.preset"):
        clothsim.Simulation(dict(HANGING, material={"preset": "no_such_cloth"}))
    with pytest.raises(ValueError, match="needs a dynamic scene"):
        clothsim.Simulation(os.path.join(SCENES, "plate_ss.json"))
    with pytest.raises(ValueError):
        clothsim.Simulation(HANGING).step(0)


def test_example_study_runs(tmp_path):
    """python/examples/bending_study.py, the notebook-style example, runs and writes its table."""
    example = os.path.join(SRC, "python", "examples", "bending_study.py")
    result = subprocess.run([sys.executable, example, "--quick", "--out", str(tmp_path / "study.csv")],
                            capture_output=True, text=True, env=dict(os.environ))
    assert result.returncode == 0, result.stderr
    rows = (tmp_path / "study.csv").read_text().strip().splitlines()
    assert rows[0] == "preset,bending_rigidity,bending_length_m,tip_sag_m,kinetic_J,elastic_J"
    assert len(rows) >= 3
