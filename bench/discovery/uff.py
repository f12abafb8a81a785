"""Universal File Format writers: dataset 55 (normal modes) and 58 (time functions, ASCII or binary 58b).

Written from the format's record layouts (I-DEAS / SDRC; the conventions pyuff reads and writes), not from
dynid's writer, so that the benchmark exercises dynid's reader on files of another origin.
"""
import numpy as np

DIRECTIONS = {"ux": 1, "uy": 2, "uz": 3}


def _text(s):
    return (s or "NONE")[:80].ljust(80)


def dataset55(mode, frequency, damping, shape, case_name):
    """One normal mode: shape = {node: (vx, vy, vz)}; 3 DOF per node (translations), real single-precision
    values (data type 2), record 8 = frequency, modal mass, viscous and hysteretic damping."""
    out = ["    -1", "    55",
           _text(f"Mode {mode}"), _text(case_name), _text("NONE"), _text("NONE"), _text("NONE"),
           f"{1:10d}{2:10d}{2:10d}{8:10d}{2:10d}{3:10d}",
           f"{2:10d}{4:10d}{1:10d}{mode:10d}",
           f"{frequency:13.5E}{1.0:13.5E}{damping:13.5E}{0.0:13.5E}"]
    for node, v in shape.items():
        out.append(f"{node:10d}")
        out.append("".join(f"{x:13.5E}" for x in v))
    out.append("    -1")
    return "\n".join(out) + "\n"


def dataset58(y, dt, node, direction, kind, record, channel_name, ref=(0, 0), binary=False, single=False):
    """One time function (function type 1). kind: 'acceleration' (m/s^2) or 'force' (N, an excitation force).
    Each channel keeps the same id line and response name over its records (one dataset per record)."""
    ordinate = {"acceleration": (12, 1, 0, "Acceleration", "m/s^2"), "force": (13, 0, 1, "Force", "N")}[kind]
    n = len(y)
    ord_type = 2 if single else 4
    head = [_text(channel_name), _text(f"record {record}"), _text("NONE"), _text("NONE"), _text("NONE"),
            f"{1:5d}{record:10d}{0:5d}{record:10d} {'NONE':<10s}{node:10d}{DIRECTIONS[direction]:4d} "
            f"{'NONE':<10s}{ref[0]:10d}{ref[1]:4d}",
            f"{ord_type:10d}{n:10d}{1:10d}{0.0:13.5E}{dt:13.5E}{0.0:13.5E}",
            f"{17:10d}{0:5d}{0:5d}{0:5d} {'Time':<20s} {'s':<20s}",
            f"{ordinate[0]:10d}{ordinate[1]:5d}{ordinate[2]:5d}{0:5d} {ordinate[3]:<20s} {ordinate[4]:<20s}",
            f"{0:10d}{0:5d}{0:5d}{0:5d} {'NONE':<20s} {'NONE':<20s}",
            f"{0:10d}{0:5d}{0:5d}{0:5d} {'NONE':<20s} {'NONE':<20s}"]
    if binary:
        data = np.asarray(y, "<f4" if single else "<f8").tobytes()
        top = (f"{-1:6d}\n{58:6d}b{1:6d}{2:6d}{11:12d}{len(data):12d}{0:6d}{0:6d}{0:12d}{0:12d}\n")
        return top.encode() + ("\n".join(head) + "\n").encode() + data + b"\n" + f"{-1:6d}\n".encode()
    if single:
        lines = ["".join(f"{v:13.5E}" for v in y[i:i + 6]) for i in range(0, n, 6)]
    else:
        lines = ["".join(f"{v:20.11E}" for v in y[i:i + 4]) for i in range(0, n, 4)]
    return ("\n".join(["    -1", "    58"] + head + lines + ["    -1"]) + "\n").encode()


def bytes_per_value(fmt):
    """Bytes per sample of the benchmark's formats: binary 58b in double or single precision, ASCII 58 in
    single precision (E13.5, six values a line)."""
    return {"binary64": 8, "binary32": 4, "ascii": 13}[fmt]

