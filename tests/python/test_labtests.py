"""hilldem.lab: gradings, genesis, the triaxial test and the study from Python give the CLI's numbers."""
import csv
import io

import numpy as np
import pytest

import hilldem
from hilldem import lab

# `hilldem triaxial`'s miniature case (tests/labtests/tests.cmake): the stored packed specimen, wet,
# one load-unload cycle at 0.02 %, loading to 0.1 %. Strains in % on the CLI, fractions in Python.
CYCLES_PERCENT, FINAL_PERCENT, RATE, FINAL_RATE = 0.02, 0.1, 0.1, 0.5


def mini_files(source_dir):
    d = source_dir / "tests" / "data" / "labtests"
    return d / "mini_packed.csv", d / "fine.csv"


def triaxial_settings():
    t = lab.TriaxialSettings()
    t.cycle_strains = [CYCLES_PERCENT / 100.0]  # the CLI's conversion, to the bit
    t.final_strain = FINAL_PERCENT / 100.0
    t.strain_rate, t.final_strain_rate = RATE, FINAL_RATE
    return t


@pytest.fixture(scope="module")
def cli_case(cli, source_dir, tmp_path_factory):
    """The miniature case run by the CLI: its output folder."""
    specimen, fine = mini_files(source_dir)
    out = tmp_path_factory.mktemp("cli")
    cli("triaxial", "--specimen", specimen, "--grading", fine, "--wet", "--cycles", CYCLES_PERCENT, "--final-strain",
        FINAL_PERCENT, "--strain-rate", RATE, "--final-strain-rate", FINAL_RATE, "--threads", 1, "--no-plot", "-q",
        "-o", out)
    return out / "fine_Hill_wet"


def read_csv(path):
    return list(csv.DictReader(io.StringIO(path.read_text())))


def test_the_study_from_python_is_the_clis(cli_case, source_dir, tmp_path):
    specimen, fine = mini_files(source_dir)
    s = lab.StudySettings()
    s.specimen_file = str(specimen)
    s.triaxial = triaxial_settings()
    s.output_dir = str(tmp_path)
    s.jobs = 1
    res = lab.study(s, [lab.CaseSpec(str(fine), lab.GrainModel.Hill, wet=True)])
    (case,) = res["cases"]
    assert case["name"] == "fine_Hill_wet"
    # The files it wrote are the CLI's, byte for byte.
    for name in ("history.csv", "loops.csv", "gsd.csv"):
        assert (tmp_path / "fine_Hill_wet" / name).read_text() == (cli_case / name).read_text(), name
    test = case["test"]
    assert test["history_csv"] == (cli_case / "history.csv").read_text()
    # The numpy columns hold what the CSV prints (9 significant digits).
    rows = read_csv(cli_case / "history.csv")
    h = test["history"]
    assert len(h["q"]) == len(rows) > 10
    np.testing.assert_allclose(h["q"], [float(r["q[Pa]"]) for r in rows], rtol=1e-8, atol=1e-6)
    np.testing.assert_allclose(h["eps_a"], [float(r["eps_a[-]"]) for r in rows], rtol=1e-8, atol=1e-15)
    assert list(h["phase"]) == [r["phase"] for r in rows]
    (loop,) = test["loops"]
    (cli_loop,) = read_csv(cli_case / "loops.csv")
    assert loop["unload_secant"] == pytest.approx(float(cli_loop["unload_secant[Pa]"]), rel=1e-8)
    assert loop["unload"]["slope"] == pytest.approx(float(cli_loop["resilient_modulus_fit[Pa]"]), rel=1e-8)
    assert loop["unload"]["slope_se"] == pytest.approx(float(cli_loop["resilient_modulus_fit_se[Pa]"]), rel=1e-8)
    assert test["peak_q"] == pytest.approx(max(float(r["q[Pa]"]) for r in rows), rel=1e-8)
    assert case["initial"]["wet_contacts"] > 0 and case["grading"]["count"] == case["initial"]["grains"]


def test_the_drivers_one_by_one_are_the_clis(cli_case, source_dir):
    """load_specimen, finalize, make_wet and triaxial called from Python: the CLI's history."""
    specimen, _ = mini_files(source_dir)
    s, packing = lab.load_specimen(specimen)
    assert s.material == "packed" and s.grains > 10 and packing.contact.fric == 0.0
    kept = s.copy()
    st = lab.StudySettings()  # the CLI's material, walls, equilibrium, suction and gap
    material = st.material
    material.model = lab.GrainModel.Hill
    phase = lab.finalize(s, material, st.test_walls, st.finalize)
    assert phase["name"] == "finalize fine_Hill" and phase["steps"] > 0
    wet = lab.make_wet(s, st.suction, st.moisture_gap, st.finalize)
    assert wet["state"]["wet_contacts"] > 0 and s.wet
    res = lab.triaxial(s, triaxial_settings())
    assert res["history_csv"] == (cli_case / "history.csv").read_text()
    assert kept.material == "packed" and not kept.wet  # copy() is independent
    sim = s.simulation()
    assert sim.ball_count == s.grains and sim.contact_count > 0
    np.testing.assert_array_equal(np.sort(2 * sim.radii), np.sort(s.diameters()))


def test_genesis_from_python_is_the_clis(cli, source_dir, tmp_path):
    """pack_specimen of a tiny vessel (the memo's scaled by 0.15, seed 42): the CLI's --pack-only file."""
    _, fine = mini_files(source_dir)
    cli("triaxial", "--pack-only", "--grading", fine, "--scale", 0.15, "--seed", 42, "--threads", 1, "-q", "-o", tmp_path)
    spec = lab.GenesisSpec()
    spec.grading = lab.grading(str(fine))
    spec.vessel_radius, spec.vessel_height = 0.085 * 0.15, 0.240 * 0.15
    spec.packing.seed = 42
    s = lab.pack_specimen(spec)
    assert [p["name"] for p in s.phases] == ["cloud", "packing"]
    mine = tmp_path / "mine.csv"
    s.save(mine, spec.packing)
    assert mine.read_text() == (tmp_path / "specimens" / "fine_hill_packed.csv").read_text()
    state = s.state()
    assert 0.2 < state["porosity"] < 0.6 and state["radial_stress"] == pytest.approx(150e3, rel=2e-2)


def test_clump_genesis_from_python_is_the_clis(cli, source_dir, tmp_path):
    """GenesisSpec.clump_template: grains as clumps, the CLI's --clump-template file to the byte."""
    _, fine = mini_files(source_dir)
    cli("triaxial", "--pack-only", "--grading", fine, "--scale", 0.15, "--seed", 42, "--threads", 1, "--clump-template",
        "elongated2", "-q", "-o", tmp_path)
    spec = lab.GenesisSpec()
    spec.grading = lab.grading(str(fine))
    spec.vessel_radius, spec.vessel_height = 0.085 * 0.15, 0.240 * 0.15
    spec.packing.seed = 42
    spec.clump_template = "elongated2"
    assert spec.clump_size == lab.SizeMeasure.EqualVolumeDiameter
    s = lab.pack_specimen(spec)
    mine = tmp_path / "mine.csv"
    s.save(mine, spec.packing)
    assert mine.read_text() == (tmp_path / "specimens" / "fine_hill_packed.csv").read_text()
    with pytest.raises(hilldem.InputError, match="unknown clump template 'dodecahedron'"):
        spec.clump_template = "dodecahedron"  # refused when set, as --clump-template is before any work


def test_clump_mix_from_python_is_the_clis(cli, source_dir, tmp_path):
    """GenesisSpec.clump_mix: a mix of templates by solid volume, as a list of tuples or a dict; the CLI's
    --clump-template NAME:FRACTION,... file to the byte, each clump's template in it."""
    _, fine = mini_files(source_dir)
    out = cli("triaxial", "--pack-only", "--grading", fine, "--scale", 0.15, "--seed", 42, "--threads", 1, "--clump-template",
              "elongated2:0.5,sphere:0.5", "-o", tmp_path)
    assert "grains: clumps of a mix by solid volume of elongated2 0.5, sphere 0.5" in out.stdout
    spec = lab.GenesisSpec()
    spec.grading = lab.grading(str(fine))
    spec.vessel_radius, spec.vessel_height = 0.085 * 0.15, 0.240 * 0.15
    spec.packing.seed = 42
    spec.clump_mix = [("elongated2", 0.5), ("sphere", 0.5)]
    assert spec.clump_template == "elongated2:0.5,sphere:0.5"
    s = lab.pack_specimen(spec)
    mine = tmp_path / "mine.csv"
    s.save(mine, spec.packing)
    assert mine.read_text() == (tmp_path / "specimens" / "fine_hill_packed.csv").read_text()
    assert s.clump_mix == [("elongated2", 0.5), ("sphere", 0.5)]
    assert sorted(set(s.clump_templates)) == ["elongated2", "sphere"]
    assert sum(s.clump_mix_fractions) == pytest.approx(1.0, abs=1e-12)
    back, _ = lab.load_specimen(mine)
    assert back.clump_templates == s.clump_templates and back.clump_mix_fractions == s.clump_mix_fractions
    spec.clump_mix = {"sphere": 0.25, "elongated2": 0.75}  # a dict: its order
    assert spec.clump_mix == [("sphere", 0.25), ("elongated2", 0.75)]
    with pytest.raises(hilldem.InputError, match=r"GenesisSpec.clump_mix: the fractions must sum to 1 \(within 1e-09\), got 1.1"):
        spec.clump_mix = [("elongated2", 0.5), ("sphere", 0.6)]
    with pytest.raises(hilldem.InputError, match=r"the fraction of sphere must be in \(0, 1\]"):
        spec.clump_mix = {"elongated2": 1.0, "sphere": 0.0}
    with pytest.raises(hilldem.InputError, match="unknown clump template 'ball'; known: sphere, elongated2"):
        spec.clump_template = "ball:0.5,sphere:0.5"
    assert spec.clump_mix == [("sphere", 0.25), ("elongated2", 0.75)]  # a refused mix leaves the last one


def test_gradings(source_dir):
    c5b = lab.grading("C5b")
    assert len(c5b.bins) == 8 and sum(b.fraction for b in c5b.bins) == pytest.approx(1.0, abs=1e-3)
    volume = 2e-4  # [m^3]
    drawn = lab.sample_grains(c5b, volume, seed=7)
    d = drawn["diameters"]
    assert np.pi / 6 * np.sum(d**3) == pytest.approx(volume, rel=0.05)
    assert len(d) == pytest.approx(lab.expected_grain_count(c5b, 1.0, volume), rel=0.1)
    np.testing.assert_array_equal(lab.sample_grains(c5b, volume, seed=7)["diameters"], d)  # seeded
    rep = lab.grading_report(c5b, d)
    assert rep["count"] == len(d) and rep["outside"] == 0 and rep["worst_bin_error"] < 0.05
    assert np.all(np.diff(rep["curve"]["realised"]) >= 0) and rep["curve"]["realised"][-1] == pytest.approx(1.0)
    assert 4.8e-3 <= rep["d50_realised"] <= 23e-3
    custom = lab.Grading("two", [lab.GradingBin(1e-3, 2e-3, 0.5), lab.GradingBin(2e-3, 4e-3, 0.5)])
    assert lab.grading_report(custom, [1.5e-3, 3e-3])["bins"]["count"].tolist() == [1, 1]


def test_bad_lab_input_names_the_value(source_dir, tmp_path):
    with pytest.raises(hilldem.InputError, match="C5x"):
        lab.grading("C5x")
    bad = source_dir / "tests" / "data" / "labtests" / "bad_sum.csv"
    with pytest.raises(hilldem.InputError, match="sum to 0.9"):
        lab.grading(str(bad))
    with pytest.raises(hilldem.InputError):
        lab.Grading("x", [lab.GradingBin(2e-3, 1e-3, 1.0)])  # d_lower > d_upper
    with pytest.raises(hilldem.InputError, match="solid_volume must be in"):
        lab.sample_grains(lab.grading("C5n"), -1.0)
    specimen, _ = mini_files(source_dir)
    s, _ = lab.load_specimen(specimen)
    t = triaxial_settings()
    t.cycle_strains = [5e-4, 2e-4]
    with pytest.raises(hilldem.InputError, match="cycle strains must be positive and increasing"):
        lab.triaxial(s, t)
    with pytest.raises(hilldem.InputError, match="only a packed specimen"):
        st = lab.StudySettings()
        lab.finalize(s, st.material)
        s.save(tmp_path / "x.csv")


def test_t307_from_python_is_the_clis(cli, source_dir, tmp_path):
    """t307 on the finalized miniature specimen (four sequences and the conditioning, three short pulses
    each): the CLI's t307_sequences.csv and fit, to the byte."""
    specimen, fine = mini_files(source_dir)
    cli("t307", "--specimen", specimen, "--grading", fine, "--sequences", "0,1,7,11,14", "--cycles", 3,
        "--averaged-cycles", 2, "--conditioning-cycles", 1, "--pulse-duration", 5e-3, "--rest-duration", 2e-3,
        "--no-plot", "-q", "-o", tmp_path)
    s, _ = lab.load_specimen(specimen)
    st = lab.StudySettings()
    material = st.material
    material.model = lab.GrainModel.Hill
    lab.finalize(s, material, st.test_walls, st.finalize)
    t = lab.T307Settings()
    table = lab.t307_base_sequences()
    assert [q.number for q in table] == list(range(16)) and table[1].confining == pytest.approx(20.7e3)
    t.sequences = [table[k] for k in (0, 1, 7, 11, 14)]
    t.timing.cycles, t.timing.averaged_cycles, t.timing.conditioning_cycles = 3, 2, 1
    t.timing.pulse_duration, t.timing.rest_duration = 5e-3, 2e-3
    r = lab.t307(s, t)
    assert r["sequences_csv"] == (tmp_path / "t307_sequences.csv").read_text()
    assert r["fitted"] and r["fit"]["r_squared"] <= 1.0 + 1e-12
    (fit,) = read_csv(tmp_path / "t307_fit.csv")
    assert r["fit"]["k1"] == pytest.approx(float(next(v for k, v in fit.items() if k.startswith("k1"))), rel=1e-6)
    rows = r["rows"]
    assert list(rows["sequence"]) == [0, 1, 7, 11, 14] and np.all(rows["modulus"][1:] > 0)
    assert len(r["cycles"]["q_peak"]) == 1 + 4 * 3
    with pytest.raises(hilldem.InputError, match="cycles"):
        bad = lab.T307Settings()
        bad.timing.cycles = 0
        lab.t307(s, bad)


def test_ctrl_c_stops_a_lab_test_between_cycles(source_dir):
    """Ctrl-C in a lab call (here T 307, far from its end): KeyboardInterrupt within about 0.05 s, the
    specimen at a cycle boundary, and nothing left asking once the call is over."""
    import os
    import signal
    import threading
    import time

    specimen, _ = mini_files(source_dir)
    s, _ = lab.load_specimen(specimen)
    st = lab.StudySettings()
    material = st.material
    material.model = lab.GrainModel.Hill
    lab.finalize(s, material, st.test_walls, st.finalize)
    before = s.simulation().steps
    t = lab.T307Settings()
    t.timing.conditioning_cycles = 1000  # minutes of work: the interrupt must come first
    timer = threading.Timer(0.5, lambda: os.kill(os.getpid(), signal.SIGINT))
    timer.start()
    start = time.monotonic()
    with pytest.raises(KeyboardInterrupt):
        lab.t307(s, t)
    assert time.monotonic() - start < 10.0
    assert s.simulation().steps > before
    phase = lab.servo_equilibrium(s, st.finalize)  # the specimen goes on, uninterrupted
    assert phase["steps"] > 0
