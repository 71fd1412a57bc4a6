#!/usr/bin/env python3
"""Write the malformed-checkpoint corpus from one valid checkpoint.

    build/hilldem run tests/data/bad_checkpoints/source.toml -o /tmp/cs
    python3 tests/data/bad_checkpoints/make_corpus.py /tmp/cs/checkpoints/ckpt-000012.hdc tests/data/bad_checkpoints

Each file is damaged in one way: container damage (truncation, bit flips, bad magic, version, sizes,
section headers), and contents that pass every checksum but are invalid (indices out of range, NaN,
wrong element sizes, a scenario that does not load or does not match, a stage past the end, a
tampered value caught by the state digest). `hilldem resume` must refuse each with exit status 2 and
a message naming the file (tests/cli/bad_checkpoints.sh, tests/io/test_checkpoint_corpus.cpp).
The layout is that of src/hilldem/io/checkpoint.hpp; CRC-32 is zlib's.
"""
import struct
import sys
import zlib
from pathlib import Path

MAGIC = b"HDMCKPT\n"
TRAILER = b"HDMEND\n\x00"


def parse(data):
    assert data[:8] == MAGIC
    version, count, body = struct.unpack_from("<IIQ", data, 8)
    pos = 28
    sections = []
    for _ in range(count):
        (nl,) = struct.unpack_from("<I", data, pos)
        name = data[pos + 4 : pos + 4 + nl].decode()
        sv, size = struct.unpack_from("<IQ", data, pos + 4 + nl)
        start = pos + 4 + nl + 12
        sections.append([name, sv, bytearray(data[start : start + size])])
        pos = start + size + 4
    return version, sections


def build(sections, version=1, fix_crc=True):
    body = bytearray()
    for name, sv, payload in sections:
        start = len(body)
        body += struct.pack("<I", len(name.encode())) + name.encode() + struct.pack("<IQ", sv, len(payload)) + payload
        body += struct.pack("<I", zlib.crc32(bytes(body[start:])) if fix_crc else 0)
    head = MAGIC + struct.pack("<IIQ", version, len(sections), len(body))
    head += struct.pack("<I", zlib.crc32(head))
    return bytes(head + body + TRAILER)


def section(sections, name):
    for s in sections:
        if s[0] == name:
            return s
    raise KeyError(name)


def string_at(payload, pos):
    (n,) = struct.unpack_from("<Q", payload, pos)
    return payload[pos + 8 : pos + 8 + n].decode(), pos + 8 + n


def ball_column_offset(payload, k):
    """Offset of the first element of ball column k in sim.balls (count, columns, then columns)."""
    pos = 8 + 4
    for _ in range(k):
        n, size = struct.unpack_from("<QI", payload, pos)
        pos += 12 + n * size
    return pos + 12


def main(src, out):
    data = Path(src).read_bytes()
    version, base = parse(data)
    out = Path(out)
    files = {}

    def mutated(fn):
        secs = [[n, v, bytearray(p)] for n, v, p in base]
        fn(secs)
        return secs

    # ---- container damage ----
    files["empty.hdc"] = b""
    files["not_a_checkpoint.hdc"] = b'title = "a scenario, not a checkpoint"\n'
    files["magic_only.hdc"] = MAGIC
    files["truncated_header.hdc"] = data[:20]
    files["truncated_in_section.hdc"] = data[: len(data) // 2]
    files["truncated_trailer.hdc"] = data[:-3]
    files["trailing_garbage.hdc"] = data + b"garbage"
    flip = bytearray(data)
    flip[len(data) // 3] ^= 0x10
    files["bit_flip_in_payload.hdc"] = bytes(flip)
    flip = bytearray(data)
    flip[9] ^= 0x01
    files["bit_flip_in_header.hdc"] = bytes(flip)
    flip = bytearray(data)
    flip[-2] ^= 0x40
    files["bit_flip_in_trailer.hdc"] = bytes(flip)
    files["future_format_version.hdc"] = build(base, version=2)
    files["zero_crc.hdc"] = build(base, fix_crc=False)
    big = bytearray(build(base))
    struct.pack_into("<Q", big, 16, 1 << 62)
    struct.pack_into("<I", big, 24, zlib.crc32(bytes(big[:24])))
    files["huge_body_size.hdc"] = bytes(big)
    # a section header whose size runs past the end (CRC of the header recomputed)
    run = bytearray(build(base))
    (nl,) = struct.unpack_from("<I", run, 28)
    struct.pack_into("<Q", run, 28 + 4 + nl + 4, 1 << 40)
    files["section_size_past_end.hdc"] = bytes(run)
    files["missing_contacts_section.hdc"] = build([s for s in base if s[0] != "sim.contacts"])
    files["missing_position_section.hdc"] = build([s for s in base if s[0] != "run.position"])
    files["duplicate_section.hdc"] = build(base + [base[-1]])
    files["newer_section_version.hdc"] = build(mutated(lambda s: section(s, "sim.balls").__setitem__(1, 99)))

    # ---- valid checksums, invalid contents ----
    def contact_key_out_of_range(s):
        p = section(s, "sim.contacts")[2]
        struct.pack_into("<I", p, 4 + 12, 0x7FFFFFFF)  # first key's ball index
    files["contact_key_out_of_range.hdc"] = build(mutated(contact_key_out_of_range))

    def contact_kind_bad(s):
        p = section(s, "sim.contacts")[2]
        p[4 + 12 + 4] = 7
    files["contact_kind_bad.hdc"] = build(mutated(contact_kind_bad))

    def radius_negative(s):
        p = section(s, "sim.balls")[2]
        struct.pack_into("<d", p, ball_column_offset(p, 1), -5e-3)
    files["ball_radius_negative.hdc"] = build(mutated(radius_negative))

    def position_nan(s):
        p = section(s, "sim.balls")[2]
        struct.pack_into("<d", p, ball_column_offset(p, 9), float("nan"))
    files["ball_position_nan.hdc"] = build(mutated(position_nan))

    def duplicate_id(s):
        p = section(s, "sim.balls")[2]
        o = ball_column_offset(p, 0)
        struct.pack_into("<q", p, o + 8, struct.unpack_from("<q", p, o)[0])
    files["ball_id_duplicate.hdc"] = build(mutated(duplicate_id))

    def element_size(s):
        p = section(s, "sim.balls")[2]
        struct.pack_into("<I", p, ball_column_offset(p, 1) - 4, 4)
    files["ball_column_element_size.hdc"] = build(mutated(element_size))

    def ball_count_huge(s):
        p = section(s, "sim.balls")[2]
        struct.pack_into("<Q", p, 0, 1 << 40)
    files["ball_count_huge.hdc"] = build(mutated(ball_count_huge))

    def wall_count_huge(s):
        struct.pack_into("<Q", section(s, "sim.walls")[2], 0, (1 << 64) - 1)
    files["wall_count_huge.hdc"] = build(mutated(wall_count_huge))

    def wall_axis(s):
        p = section(s, "sim.walls")[2]
        name, pos = string_at(p, 8)
        pos += 8 + 4 + 24 * 5  # groups, shape, point, normal, 3 vertices
        struct.pack_into("<I", p, pos, 9)
    files["wall_axis_bad.hdc"] = build(mutated(wall_axis))

    def damping(s):
        struct.pack_into("<d", section(s, "sim.settings")[2], 24, 1.5)
    files["settings_damping_out_of_range.hdc"] = build(mutated(damping))

    def clock(s):
        struct.pack_into("<q", section(s, "sim.clock")[2], 8, -5)
    files["clock_negative_steps.hdc"] = build(mutated(clock))

    def groups(s):
        struct.pack_into("<Q", section(s, "sim.groups")[2], 0, 65)
    files["group_count_65.hdc"] = build(mutated(groups))

    def scenario_text(text):
        def f(s):
            p = section(s, "run.scenario")[2]
            name, pos = string_at(p, 0)
            p[:] = struct.pack("<Q", len(name)) + name.encode() + struct.pack("<Q", len(text)) + text.encode()
        return f
    files["scenario_not_toml.hdc"] = build(mutated(scenario_text("[[ball]\nid = ")))
    files["scenario_mismatch.hdc"] = build(mutated(scenario_text(
        '[[material]]\nname = "g"\ndensity = 2650\n[[ball]]\nid = 1\nposition = [0, 0, 0]\nradius = 1e-3\nmaterial = "g"\n')))

    def stage_past_end(s):
        struct.pack_into("<Q", section(s, "run.position")[2], 0, 999)
    files["position_stage_past_end.hdc"] = build(mutated(stage_past_end))

    def steps_past_stage(s):
        struct.pack_into("<q", section(s, "run.position")[2], 8, 10**9)
    files["position_steps_past_stage.hdc"] = build(mutated(steps_past_stage))

    def servo_name(s):
        p = section(s, "run.servos")[2]
        p[8 + 8] = ord("X")
    files["servo_name_mismatch.hdc"] = build(mutated(servo_name))

    def snapshot_count(s):
        struct.pack_into("<Q", section(s, "run.outputs")[2], 9, 1 << 50)
    files["snapshot_count_huge.hdc"] = build(mutated(snapshot_count))

    def blowup(s):
        p = section(s, "run.meta")[2]
        kind, pos = string_at(p, 0)
        p[:] = struct.pack("<Q", 7) + b"blow-up" + p[pos:]
    files["blowup_state_not_resumable.hdc"] = build(mutated(blowup))

    def tampered_velocity(s):
        p = section(s, "sim.balls")[2]
        o = ball_column_offset(p, 10)
        struct.pack_into("<d", p, o, struct.unpack_from("<d", p, o)[0] + 1e-3)
    files["tampered_state_digest_mismatch.hdc"] = build(mutated(tampered_velocity))

    def keep_zero(s):
        p = section(s, "run.settings")[2]
        # snapshots: 6 bytes of flags and a count, then the folder string; checkpoints: flag, i64, f64, flag, then keep.
        folder, pos = string_at(p, 1 + 8 + 4)
        struct.pack_into("<q", p, pos + 1 + 8 + 8 + 1, 0)
    files["settings_keep_zero.hdc"] = build(mutated(keep_zero))

    # sim.cycle: forces_ready u8, rebuild_needed u8, rebuilds i64, unassigned u64, positions column
    # (u64 count, u32 element size, data), wall travel f64; version 2: then rows complete u8.
    def cycle_rebuilds_negative(s):
        struct.pack_into("<q", section(s, "sim.cycle")[2], 2, -5)
    files["cycle_rebuilds_negative.hdc"] = build(mutated(cycle_rebuilds_negative))

    def cycle_wall_travel_nan(s):
        _, version, p = section(s, "sim.cycle")
        struct.pack_into("<d", p, len(p) - 8 - (1 if version >= 2 else 0), float("nan"))
    files["cycle_wall_travel_nan.hdc"] = build(mutated(cycle_wall_travel_nan))

    def cycle_positions_for_other_balls(s):
        p = section(s, "sim.cycle")[2]
        n, size = struct.unpack_from("<QI", p, 18)
        # one ball fewer: drop its element and lower the count
        del p[18 + 12 + (n - 1) * size : 18 + 12 + n * size]
        struct.pack_into("<Q", p, 18, n - 1)
    files["cycle_positions_for_other_balls.hdc"] = build(mutated(cycle_positions_for_other_balls))

    # What each refusal must say (tests/io/test_checkpoint_corpus.cpp checks it, so that a stale corpus
    # cannot pass for the wrong reason).
    expect = {
        "empty.hdc": "empty file", "not_a_checkpoint.hdc": "not a hilldem checkpoint", "magic_only.hdc": "shorter than the header",
        "truncated_header.hdc": "shorter than the header", "truncated_in_section.hdc": "truncated checkpoint",
        "truncated_trailer.hdc": "truncated checkpoint", "trailing_garbage.hdc": "trailing data",
        "bit_flip_in_payload.hdc": "fails its checksum", "bit_flip_in_header.hdc": "header checksum mismatch",
        "bit_flip_in_trailer.hdc": "end marker", "future_format_version.hdc": "format version 2",
        "zero_crc.hdc": "fails its checksum", "huge_body_size.hdc": "the header announces", "section_size_past_end.hdc": "runs past the end",
        "missing_contacts_section.hdc": "no section 'sim.contacts'", "missing_position_section.hdc": "no section 'run.position'",
        "duplicate_section.hdc": "appears twice", "newer_section_version.hdc": "has version 99",
        "contact_key_out_of_range.hdc": "refers to ball index", "contact_kind_bad.hdc": "has kind 7",
        "ball_radius_negative.hdc": "radius that is not positive", "ball_position_nan.hdc": "non-finite 'position'",
        "ball_id_duplicate.hdc": "appears twice", "ball_column_element_size.hdc": "incompatible hilldem build",
        "ball_count_huge.hdc": "exceeds the limit", "wall_count_huge.hdc": "exceeds the limit", "wall_axis_bad.hdc": "has axis 9",
        "settings_damping_out_of_range.hdc": "local_damping", "clock_negative_steps.hdc": "out of range",
        "group_count_65.hdc": "exceeds the limit 64", "scenario_not_toml.hdc": "TOML syntax error",
        "scenario_mismatch.hdc": "does not match its scenario", "position_stage_past_end.hdc": "stage 1000 of a scenario",
        "position_steps_past_stage.hdc": "steps done inside a stage", "servo_name_mismatch.hdc": "is not the scenario's servo",
        "snapshot_count_huge.hdc": "exceeds the limit", "blowup_state_not_resumable.hdc": "state of a blow-up",
        "tampered_state_digest_mismatch.hdc": "differs from the saved", "settings_keep_zero.hdc": "output settings out of range",
        "cycle_rebuilds_negative.hdc": "negative rebuild count", "cycle_wall_travel_nan.hdc": "wall travel must be finite",
        "cycle_positions_for_other_balls.hdc": "positions at the last rebuild for 2 balls",
    }
    assert set(expect) == set(files), set(files) ^ set(expect)
    out.mkdir(parents=True, exist_ok=True)
    for name, content in sorted(files.items()):
        (out / name).write_bytes(content)
    (out / "expected.txt").write_text("".join(f"{name}: {expect[name]}\n" for name in sorted(files)))
    print(f"wrote {len(files)} files and expected.txt to {out}")


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2])
