#!/usr/bin/env python3
"""sagcal's instructions per pose per iteration split by what they do (issue 18).

    cargo build --release --manifest-path peers/Cargo.toml
    python3 peers/split_by_kernel.py            # N1=100 N2=300 K1=1 K2=3, as count_instructions.sh

Four callgrind runs of `sagcal-peers --count sagcal` with `--dump-instr=yes`
(poses N1, N2; linearisation budgets K1, K2), counting only inside
`counted_solve`; every instruction address gets the double difference
[C(N2,K2) - C(N2,K1) - C(N1,K2) + C(N1,K1)] / ((N2 - N1)(K2 - K1)), one
pose's share of one iteration, as in `count_instructions.sh`. Each address
is then put in one class by the innermost function of this repository that
the debug information places it in (`addr2line -i -f -C`; inlined frames
included), or, for code in shared libraries, by callgrind's function name:

  evaluation      generated/ (the SymForce functions) and the libm calls they make
  J^T J, J^T r    the multiply-add loops of the accumulation (gram_block, run_product,
                  add_run_product, add_run_gradient)
  elimination     the per-pose Cholesky, W = L^-1 B and W^T W (gram_block under schur)
  substitutions   the forward / backward substitutions of the solve and the reduced system
  rest            everything else, by module (the factors' wrappers, whitening, the
                  gathers and copies, the loop over factors, zeroing of H, ...)

The first four are the arithmetic a Levenberg-Marquardt step with the block
elimination performs in sagcal's formulation (exact sums in a fixed order, no
FMA); "rest" is what a perfect implementation could remove.
"""
import collections
import os
import re
import subprocess
import sys

ROOT = os.path.dirname(os.path.abspath(__file__))
BINARY = os.environ.get("BINARY", os.path.join(ROOT, "target/release/sagcal-peers"))
OUT = os.environ.get("OUT", os.path.join(ROOT, "target/callgrind"))
N1, N2 = int(os.environ.get("N1", 100)), int(os.environ.get("N2", 300))
K1, K2 = int(os.environ.get("K1", 1)), int(os.environ.get("K2", 3))
LIBM = re.compile(r"(exp|expm1|log|log1p|sinh|cosh|tanh|hypot|sqrt|atan|atan2|sin|cos|sincos|asinh|acosh|pow)\b")


def run(poses, iterations):
    """One callgrind run; its file."""
    path = f"{OUT}/split-{poses}-{iterations}.out"
    os.makedirs(OUT, exist_ok=True)
    command = ["valgrind", "--tool=callgrind", "--dump-instr=yes", f"--callgrind-out-file={path}",
               "--toggle-collect=*counted_solve*", BINARY, "--count", "sagcal",
               "--poses", str(poses), "--iterations", str(iterations)]
    done = subprocess.run(command, capture_output=True, text=True)
    if done.returncode != 0:
        sys.exit(done.stderr)
    return path


def self_costs(path):
    """Self instructions by (function name, address)."""
    names, costs = {}, collections.Counter()
    function, address, after_call = None, 0, False
    for line in open(path):
        line = line.rstrip("\n")
        m = re.match(r"^(c?)fn=\((\d+)\)(?: (.*))?$", line)
        if m:
            called, key, name = m.groups()
            if name:
                names[key] = name
            if not called:
                function = names[key]
            continue
        if line.startswith("calls="):
            after_call = True  # the next cost line is the call's inclusive cost
            continue
        if not line or line[0] not in "0123456789+-*":
            continue
        fields = line.split()
        token = fields[0]
        if token == "*":
            pass
        elif token[0] == "+":
            address += int(token[1:], 0)
        elif token[0] == "-":
            address -= int(token[1:], 0)
        else:
            address = int(token, 0)
        if after_call:
            after_call = False
            continue
        if len(fields) >= 3:
            costs[(function, address)] += int(fields[2])
    return costs


def frames(addresses):
    """Inlined frames (function, file) of each address, innermost first."""
    result = {}
    for chunk in range(0, len(addresses), 2000):
        part = addresses[chunk:chunk + 2000]
        out = subprocess.run(["addr2line", "-a", "-i", "-f", "-C", "-e", BINARY] + [hex(a) for a in part],
                             capture_output=True, text=True).stdout.splitlines()
        current, k = None, 0
        while k < len(out):
            if out[k].startswith("0x"):
                current = int(out[k], 16)
                result[current] = []
                k += 1
                continue
            result[current].append((out[k], out[k + 1] if k + 1 < len(out) else ""))
            k += 2
    return result


def classify(function, stack):
    """The class of one address."""
    if function and ("memset" in function or "memcpy" in function or "memmove" in function):
        return "rest: zeroing and copying buffers (memset, memcpy)"
    if function and LIBM.search(function.split("@")[0].strip("_").replace("_finite", "").replace("_fma", "")) \
            and "sagcal" not in function:
        return "evaluation"
    ours = [(f, path) for f, path in stack if "/src/" in path or "/generated/" in path]
    ours = [(f, path) for f, path in ours if "/rustc/" not in path and "/.cargo/" not in path]
    if not ours:
        return "rest: other (" + (function or "?")[:40] + ")"
    name, path = ours[0]
    outer = " ".join(f for f, _ in ours)
    if "/generated/" in path or "sagcal::generated::" in name:
        return "evaluation"
    if "gram_block" in name:
        return "elimination (L, W = L^-1 B, W^T W)" if "schur" in outer or "elimination" in outer else "J^T J and J^T r"
    if any(k in name for k in ("run_product", "add_run_product", "add_run_gradient")):
        return "J^T J and J^T r"
    if "simd/elimination.rs" in path and any(k in name for k in ("cholesky", "forward_substitute_rows")):
        return "elimination (L, W = L^-1 B, W^T W)"
    if ("schur.rs" in path or "dense.rs" in path) and any(k in name for k in ("cholesky_in_place", "eliminate_group")):
        return "elimination (L, W = L^-1 B, W^T W)"
    if ("schur.rs" in path or "dense.rs" in path) and any(k in name for k in ("forward_substitute", "backward_substitute",
                                                       "reduce_right_hand_side", "back_substitute_group")):
        return "substitutions (solve)"
    module = re.search(r"sagcal::(\w+)::(\w+)", name)
    where = f"{module.group(1)}::{module.group(2)}" if module else name[:40]
    return f"rest: {where}"


def main():
    files = {(n, k): run(n, k) for n in (N1, N2) for k in (K1, K2)}
    costs = {key: self_costs(path) for key, path in files.items()}
    keys = set().union(*costs.values())
    scale = (N2 - N1) * (K2 - K1)
    per = {key: (costs[(N2, K2)][key] - costs[(N2, K1)][key] - costs[(N1, K2)][key] + costs[(N1, K1)][key]) / scale
           for key in keys}
    stacks = frames(sorted({a for _, a in keys}))
    classes = collections.Counter()
    for (function, address), value in per.items():
        classes[classify(function, stacks.get(address, []))] += value
    total = sum(classes.values())
    arithmetic = sum(v for k, v in classes.items() if not k.startswith("rest") and k != "evaluation")
    rest = sum(v for k, v in classes.items() if k.startswith("rest"))
    print(f"sagcal, instructions per pose per iteration ({N1}/{N2} poses, {K1}/{K2} linearisations): {total:.0f}")
    for name, value in sorted(classes.items(), key=lambda kv: (kv[0].startswith("rest"), -kv[1])):
        if abs(value) >= 0.5:
            print(f"  {value:8.0f}  {name}")
    evaluation = classes["evaluation"]
    print(f"evaluation {evaluation:.0f}; linear-algebra arithmetic {arithmetic:.0f} "
          f"({arithmetic / evaluation:.2f} x the evaluation); rest {rest:.0f} ({rest / evaluation:.2f} x)")


if __name__ == "__main__":
    main()
