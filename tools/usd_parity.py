#!/usr/bin/env python3
"""Parity of `luxeval lights --json` with Pixar's usd-core over a corpus of USD stages.

    python3 tools/usd_parity.py /path/to/OpenUSD/pxr --luxeval target/debug/luxeval [--json OUT]

A *light stage* is a .usd/.usda/.usdc/.usdz file (under a folder named `testenv`, unless
--any-folder or the file is named on the command line) that usd-core's Usd.Stage.Open opens and
whose Traverse() holds at least one prim with UsdLux.LightAPI. For each one, in sorted order, the
script runs `luxeval lights --json STAGE` (60 s per stage) and compares it light by light with
usd-core:

- the set of light paths (usd-core: prims with LightAPI, traversing instance proxies as luxeval
  does), then their order;
- the time: luxeval's default, the root layer's startTimeCode when authored, else EarliestTime;
  everything below is read by usd-core at that time;
- each light's type, visibility and world matrix (UsdGeom.XformCache);
- every input luxeval reports: its value (attribute Get() at that time; where usd-core has no
  value, a blocked one, the schema's fallback from the prim definition) and its authored flag
  (HasAuthoredValue()). Floats, colours and matrix entries agree within a relative 1e-6.

Every expected value comes from usd-core. Prints one line per failing stage (why luxeval
refused it, or its first mismatch with usd-core), then the summary line
`N of M light stages: luxeval exits 0 and every light equals usd-core` and the failing stages
counted by reason. A refusal's reason names the construct on the line luxeval points at (a `//`
comment, a `config` qualifier, a number written `.1` or `0.`, an asset written as a string, a
reference to a .mtlx layer) where it can tell, else luxeval's message with names and numbers
elided. `--json OUT` writes every stage's result. Needs only usd-core (Python 3.11).
"""

import argparse
import contextlib
import hashlib
import json
import math
import os
import re
import shutil
import subprocess
import sys
from collections import Counter

from pxr import Usd, UsdGeom, UsdLux

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(HERE)
EXTENSIONS = (".usd", ".usda", ".usdc", ".usdz")
REL_TOL = 1e-6
SUMMARY = "{ok} of {total} light stages: luxeval exits 0 and every light equals usd-core"


# ---------------------------------------------------------------------------------------------
# Finding the light stages


@contextlib.contextmanager
def quiet_stderr():
    """usd-core prints its diagnostics (coding errors, warnings of unrelated schemas) straight to
    file descriptor 2; over a whole corpus they would bury the report."""
    sys.stderr.flush()
    saved = os.dup(2)
    devnull = os.open(os.devnull, os.O_WRONLY)
    try:
        os.dup2(devnull, 2)
        yield
    finally:
        sys.stderr.flush()
        os.dup2(saved, 2)
        os.close(saved)
        os.close(devnull)


def candidate_files(args):
    """(absolute path, path shown) of every candidate file, sorted and without duplicates."""
    seen = {}
    for arg in args.paths:
        if os.path.isdir(arg):
            root = os.path.abspath(arg)
            for dirpath, dirnames, filenames in os.walk(root):
                dirnames.sort()
                rel_dir = os.path.relpath(dirpath, root)
                parts = [] if rel_dir == "." else rel_dir.split(os.sep)
                if not args.any_folder and "testenv" not in parts:
                    continue
                for name in sorted(filenames):
                    if name.lower().endswith(EXTENSIONS):
                        path = os.path.join(dirpath, name)
                        seen.setdefault(path, os.path.relpath(path, root))
        elif os.path.isfile(arg):
            seen.setdefault(os.path.abspath(arg), arg)
        else:
            sys.exit(f"usd_parity.py: {arg}: no such file or directory")
    return sorted(seen.items())


def open_stage(path):
    try:
        with quiet_stderr():
            return Usd.Stage.Open(path)
    except Exception:  # Tf.ErrorException: usd-core refuses it, so it is not a light stage
        return None


def is_light_stage(stage):
    return stage is not None and any(p.HasAPI(UsdLux.LightAPI) for p in stage.Traverse())


# ---------------------------------------------------------------------------------------------
# What usd-core says


def stage_time(stage):
    """luxeval's default time: the root layer's startTimeCode when authored, else EarliestTime."""
    layer = stage.GetRootLayer()
    if layer.HasStartTimeCode():
        t = float(layer.startTimeCode)
        return Usd.TimeCode(t), {"rule": "start_time_code", "time": t}
    return Usd.TimeCode.EarliestTime(), {"rule": "earliest"}


def usd_lights(stage):
    """The prims with LightAPI, in traversal order, instance proxies included (as luxeval)."""
    pred = Usd.TraverseInstanceProxies(Usd.PrimDefaultPredicate)
    return [p for p in stage.Traverse(pred) if p.HasAPI(UsdLux.LightAPI)]


def plain(v):
    """A usd-core value as JSON-like Python: float, bool, str, list, or an asset dict."""
    if v is None:
        return None
    if isinstance(v, bool):
        return v
    if isinstance(v, (int, float)):
        return float(v)
    if isinstance(v, str):
        return v
    if hasattr(v, "resolvedPath"):  # Sdf.AssetPath
        return {"authored": v.path, "resolved": v.resolvedPath or None}
    try:
        return [plain(x) for x in v]
    except TypeError:
        return str(v)


def usd_input(prim, name, tc):
    """usd-core's value and authored flag of one attribute, or None when the prim has none."""
    attr = prim.GetAttribute(name)
    if not attr or not attr.IsValid():
        return None
    value = attr.Get(tc)
    if value is None:
        # Blocked (or never given a value): what a reader falls back to is the schema's value.
        value = prim.GetPrimDefinition().GetAttributeFallbackValue(name)
    return {"value": plain(value), "authored": bool(attr.HasAuthoredValue())}


# ---------------------------------------------------------------------------------------------
# Comparing


def close(a, b):
    if isinstance(a, bool) or isinstance(b, bool):
        return a is b
    if a == b:
        return True
    if not isinstance(a, (int, float)) or not isinstance(b, (int, float)):
        return False
    if math.isnan(a) and math.isnan(b):
        return True
    return abs(a - b) <= REL_TOL * max(abs(a), abs(b))


def same_resolved(ours, theirs):
    if not ours and not theirs:
        return True
    if not ours or not theirs:
        return False
    return os.path.normpath(ours) == os.path.normpath(theirs)


def same_value(ours, theirs):
    if isinstance(ours, dict) or isinstance(theirs, dict):
        if not isinstance(theirs, dict):
            # An unauthored asset without fallback: usd-core has no value, luxeval an empty one.
            return theirs is None and isinstance(ours, dict) and not ours.get("authored") \
                and not ours.get("resolved")
        if not isinstance(ours, dict):
            return False
        return ours.get("authored") == theirs["authored"] and same_resolved(
            ours.get("resolved"), theirs["resolved"])
    if isinstance(ours, list) or isinstance(theirs, list):
        return isinstance(ours, list) and isinstance(theirs, list) and len(ours) == len(theirs) \
            and all(close(a, b) for a, b in zip(ours, theirs))
    return close(ours, theirs)


def short(v):
    return json.dumps(v, separators=(",", ":"))


def compare_light(ours, prim, tc, cache):
    """Every mismatch of one light: (kind, message)."""
    path = ours["path"]
    out = []
    if ours.get("usd_type") != str(prim.GetTypeName()):
        out.append(("type", f"{path}: type {ours.get('usd_type')} vs usd-core {prim.GetTypeName()}"))
    img = UsdGeom.Imageable(prim)
    visible = (img.ComputeVisibility(tc) != UsdGeom.Tokens.invisible) if img else True
    if ours.get("visible") != visible:
        out.append(("visibility", f"{path}: visible {ours.get('visible')} vs usd-core {visible}"))
    m = cache.GetLocalToWorldTransform(prim)
    want = [[float(m[r][c]) for c in range(4)] for r in range(4)]
    got = ours.get("world")
    if got is None:
        out.append(("world matrix", f"{path}: no world matrix ({ours.get('warning')}) vs usd-core {short(want)}"))
    else:
        for r in range(4):
            for c in range(4):
                g, w = got[r][c], want[r][c]
                if abs(g - w) > REL_TOL * max(abs(w), abs(g), 1.0):
                    out.append(("world matrix", f"{path}: world[{r}][{c}] {g!r} vs usd-core {w!r}"))
    for inp in ours.get("inputs", []):
        name = inp["name"]
        theirs = usd_input(prim, name, tc)
        if theirs is None:
            out.append(("input usd-core lacks", f"{path}: {name}: usd-core has no such attribute"))
            continue
        if not same_value(inp["value"], theirs["value"]):
            out.append(("input value",
                        f"{path}: {name} = {short(inp['value'])} vs usd-core {short(theirs['value'])}"))
        if bool(inp["authored"]) != theirs["authored"]:
            out.append(("input authored",
                        f"{path}: {name}: authored {inp['authored']} vs usd-core {theirs['authored']}"))
    return out


def compare_stage(stage, report):
    """(mismatches, number of lights compared) of luxeval's JSON report against usd-core."""
    tc, rule = stage_time(stage)
    out = []
    if report.get("time") != rule:
        out.append(("time", f"time {short(report.get('time'))} vs {short(rule)} (root layer's startTimeCode)"))
    prims = usd_lights(stage)
    theirs = [str(p.GetPath()) for p in prims]
    ours = [l["path"] for l in report.get("lights", [])]
    if set(ours) != set(theirs):
        extra = sorted(set(ours) - set(theirs))
        missing = sorted(set(theirs) - set(ours))
        out.append(("light paths", f"lights: luxeval only {extra}, usd-core only {missing}"))
    elif ours != theirs:
        out.append(("light order", f"light order {ours} vs usd-core {theirs}"))
    by_path = {str(p.GetPath()): p for p in prims}
    cache = UsdGeom.XformCache(tc)
    n = 0
    for light in report.get("lights", []):
        prim = by_path.get(light["path"])
        if prim is None:
            continue
        n += 1
        out.extend(compare_light(light, prim, tc, cache))
    return out, n


# ---------------------------------------------------------------------------------------------
# Why luxeval refused a stage

LOCATION = re.compile(r"^(?:error:\s*)?(/[^:]+):(\d+):")


def construct_at(message):
    """The construct on the line luxeval's message points at, if it is one we know by sight."""
    m = LOCATION.match(message)
    if not m:
        return None
    try:
        with open(m.group(1), encoding="utf-8", errors="replace") as f:
            lines = f.read().splitlines()
        line = lines[int(m.group(2)) - 1]
    except (OSError, IndexError, ValueError):
        return None
    code = re.sub(r'"(?:[^"\\]|\\.)*"|@[^@]*@', '""', line)  # strings and assets hide nothing
    if "//" in code:
        return "text: `//` comment"
    if re.match(r"\s*config\b", code):
        return "text: `config` qualifier"
    if re.search(r"(?<![\w.])\.\d|\d\.(?![\d\w])", code):
        return "text: number written `.1` or `0.`"
    return None


def refusal_reason(message):
    if re.search(r"no file format registered for \S+\.mtlx", message):
        return "reference to a MaterialX .mtlx layer"
    if "Asset reference expected, got String" in message:
        return "text: asset value written as a string"
    known = construct_at(message)
    if known:
        return known
    m = re.search(r"no file format registered for \S+?(\.\w+)\b", message)
    if m:
        return f"no file format for {m.group(1)}"
    # luxeval's message with paths, quoted names and numbers elided.
    msg = LOCATION.sub("", message).strip()
    msg = re.sub(r"\(a (?:sublayer|reference|payload)[^)]*\)", "", msg)
    msg = re.sub(r"/\S+", "PATH", msg)
    msg = re.sub(r'"[^"]*"|\'[^\']*\'|`[^`]*`', "NAME", msg)
    msg = re.sub(r"\d+(?:\.\d+)?", "N", msg)
    return "refused: " + " ".join(msg.split())[:120]


def first_error_line(stderr):
    lines = [l.strip() for l in stderr.splitlines() if l.strip()]
    for l in lines:
        if l.startswith("error"):
            return l
    return lines[0] if lines else "(no message)"


# ---------------------------------------------------------------------------------------------


def run_luxeval(luxeval, path, timeout):
    try:
        p = subprocess.run([luxeval, "lights", "--json", path], capture_output=True, text=True,
                           timeout=timeout, errors="replace")
    except subprocess.TimeoutExpired:
        return None, "", f"timed out after {timeout} s"
    return p.returncode, p.stdout, p.stderr


def check(path, shown, stage, args, roots):
    result = {"stage": shown, "ok": False}
    code, out, err = run_luxeval(args.luxeval, path, args.timeout)
    result["exit"] = code
    tidy = lambda s: s.replace(roots, "") if roots else s  # noqa: E731
    if code is None:
        result.update(reason="timeout", detail=err)
        return result
    if code != 0:
        line = first_error_line(err)
        result["detail"] = tidy(line)
        if code < 0:
            result["reason"] = f"crash (signal {-code})"
        elif code not in (1, 2):
            result["reason"] = f"crash (exit {code})"
        elif code == 1:
            result["reason"] = "runtime failure (exit 1)"
        else:
            result["reason"] = refusal_reason(line)
        return result
    try:
        report = json.loads(out)
    except json.JSONDecodeError as e:
        result.update(reason="unreadable JSON", detail=str(e))
        return result
    with quiet_stderr():
        mismatches, n = compare_stage(stage, report)
    result["lights"] = n
    if mismatches:
        result["reason"] = "mismatch: " + mismatches[0][0]
        result["detail"] = tidy(mismatches[0][1])
        result["mismatches"] = [{"kind": k, "detail": tidy(d)} for k, d in mismatches]
    else:
        result["ok"] = True
    return result


def binary_identity(luxeval):
    """The binary's sha256 and `--version`, so that a saved result says what it measured."""
    path = shutil.which(luxeval) or luxeval
    try:
        with open(path, "rb") as f:
            digest = hashlib.sha256(f.read()).hexdigest()
    except OSError:
        digest = None
    try:
        version = subprocess.run([path, "--version"], capture_output=True, text=True,
                                 timeout=60).stdout.strip()
    except (OSError, subprocess.TimeoutExpired):
        version = None
    return {"path": path, "sha256": digest, "version": version}


def default_luxeval():
    found = shutil.which("luxeval")
    if found:
        return found
    local = os.path.join(REPO, "target", "debug", "luxeval")
    return local if os.path.exists(local) else "luxeval"


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                 epilog="\n\n".join(__doc__.split("\n\n")[1:]),
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("paths", nargs="+", help="directories to search, or stage files")
    ap.add_argument("--luxeval", default=default_luxeval(),
                    help="the luxeval binary (default: luxeval on PATH, else target/debug/luxeval)")
    ap.add_argument("--json", metavar="OUT", help="write every stage's result here")
    ap.add_argument("--timeout", type=float, default=60, help="seconds per stage (default 60)")
    ap.add_argument("--any-folder", action="store_true",
                    help="search every folder of a directory, not only those under a `testenv` folder")
    args = ap.parse_args()
    if shutil.which(args.luxeval) is None and not os.access(args.luxeval, os.X_OK):
        sys.exit(f"usd_parity.py: no luxeval binary at {args.luxeval} (--luxeval PATH)")
    args.luxeval = os.path.abspath(args.luxeval) if os.sep in args.luxeval else args.luxeval
    dirs = [os.path.abspath(p) for p in args.paths if os.path.isdir(p)]
    roots = os.path.commonpath(dirs) + os.sep if len(dirs) == 1 else ""

    results = []
    for path, shown in candidate_files(args):
        stage = open_stage(path)
        if not is_light_stage(stage):
            continue
        r = check(path, shown, stage, args, roots)
        results.append(r)
        if not r["ok"]:
            exit_code = "timeout" if r["exit"] is None else f"exit {r['exit']}"
            print(f"FAIL {shown}: {exit_code}: {r['detail']}", flush=True)
        del stage

    ok = sum(r["ok"] for r in results)
    reasons = Counter(r["reason"] for r in results if not r["ok"])
    print(SUMMARY.format(ok=ok, total=len(results)))
    lights = sum(r.get("lights", 0) for r in results)
    print(f"  ({lights} lights compared in the {sum(r['exit'] == 0 for r in results)} stages luxeval read)")
    for reason, n in sorted(reasons.items(), key=lambda kv: (-kv[1], kv[0])):
        print(f"  {n:4d}  {reason}")
    if args.json:
        with open(args.json, "w") as f:
            json.dump({
                "usd_version": ".".join(str(x) for x in Usd.GetVersion()),
                "luxeval": binary_identity(args.luxeval),
                "summary": {"ok": ok, "total": len(results), "reasons": dict(sorted(reasons.items()))},
                "stages": results,
            }, f, indent=1)
            f.write("\n")
    return 0 if ok == len(results) else 1


if __name__ == "__main__":
    sys.exit(main())
