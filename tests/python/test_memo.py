"""The memo's values from Python equal `hilldem verify`'s."""
import csv
import io

import hilldem


def test_verify_from_python_equals_the_cli(cli):
    run = cli("verify", "-q", "--csv", "/dev/stdout")
    text = run.stdout[run.stdout.index("id,quantity,memo_value"):]
    rows = [r for r in csv.DictReader(io.StringIO(text)) if r.get("pass") in ("pass", "fail")]
    py = hilldem.verify()
    assert len(rows) == len(py) > 20
    for r in rows:
        mine = py[r["id"]]
        assert (format(mine["computed"], ".9g") if mine["produced"] else "") == r["computed"], r["id"]
        assert mine["pass"] == (r["pass"] == "pass")
    assert all(v["pass"] for v in py.values())


def test_two_grains_from_python_give_the_memos_values(source_dir):
    """examples/two_grains_hill.toml run from Python: every probe is verify's value (H1-H8, D2, D3)."""
    sim = hilldem.load_scenario(source_dir / "examples" / "two_grains_hill.toml")
    probes = sim.run_stages()["probes"]
    reference = hilldem.verify()
    checked = 0
    for label, p in probes.items():
        if label in reference and reference[label]["scenario"].endswith("two_grains_hill.toml"):
            assert p["value"] == reference[label]["computed"], label
            checked += 1
    assert checked >= 8
    # H2: the effective radius R_e = R1 R2 / (R1 + R2) of the two grains (7.5 mm and 5 mm) [m]
    assert abs(probes["H2"]["value"] - 7.5e-3 * 5e-3 / 12.5e-3) < 1e-15
