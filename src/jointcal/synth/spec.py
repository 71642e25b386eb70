"""Truth specs for synthetic campaigns: defaults, loading (YAML or JSON), validation.

Keys (units lbf, in, s, g):

seed                 int, required: every random draw follows from it.
first_sequence       int >= 1, optional (default 1): the place of the spec's first run in the
                     lab's run sequence, for a campaign generated in parts (one spec per sweep
                     rate): a drift along the sequence (joint_settling) runs on across them.
sample_rate_hz       output sample rate of the files.
file_format          csv | csv.gz | mat.
slug_weight_lbf      slug weight (mass = weight / 386.089).
sweep                f_start_hz, f_stop_hz (the band, low or high first), rate_hz_per_s,
                     ramp_s (cosine ramps), tail_s (free decay recorded after the sweep).
series               list of {level_g, directions: [up, down], repeats}: the test order
                     of each assembly (the paper's Table 3.1 by default); for a shaker
                     rig (rig.reference force or voltage) level_V, the amplifier's
                     voltage amplitude (V), instead of level_g.
assemblies           {name: {Fs, KT, chi, beta, k, zeta_v}} (Table 3.2 by default); the
                     four joint keys may all be left out (a linear structure),
                     weight_lbf gives an assembly its own slug weight, and backbone_share
                     s (force or voltage rigs) makes s of the joint's force elastic along
                     its backbone: a joint softening more than Masing allows for its
                     damping (`jointcal.synth.non_masing`).
rig                  reference: base (the paper's closed-loop base-acceleration control,
                     default) | force | voltage: an open-loop electrodynamic shaker on the
                     slug (`jointcal.synth.shaker`), recording the force gauge (force_lbf,
                     manifest level_lbf = the force amplitude over the sweep, lbf) or the
                     amplifier voltage (drive_V, level_V); shaker: armature_weight_lbf,
                     suspension_hz, suspension_zeta, bl_lbf_per_A, coil_ohm, coil_mH;
                     second_mode (optional): {f_hz, zeta, weight_lbf}, a linear mode of
                     the structure at the driving point beside the jointed one.
                     The sweep's rate_hz_per_s sets fast chirps as well (eta =
                     rate / (f zeta)^2 from 0.1 to 20 and beyond).
measurement          noise_fraction (of each channel's RMS), dc_offset_g (std), bits,
                     full_scale_g {base, response} ('auto' or g), oversample (simulation
                     rate / output rate), antialias_order, antialias_cutoff (x output
                     rate), ripple (controller amplitude ripple), distortion [2nd, 3rd].
effect               {name, params} or effect_file (YAML/JSON holding {name, params},
                     relative to the spec): the hidden effect, 'none' by default; an
                     optional ``also: {name, params}`` hides a second one at the same time.
"""
from __future__ import annotations

import copy
import json
import os
from pathlib import Path

import yaml

from .hidden import effect_defaults
from .shaker import Shaker, StructureMode

__all__ = ["DEFAULT_SPEC", "load_spec"]

DEFAULT_SPEC: dict = {
    "sample_rate_hz": 12800.0,
    "file_format": "csv.gz",
    "slug_weight_lbf": 2.65,
    "sweep": {"f_start_hz": 700.0, "f_stop_hz": 2500.0, "rate_hz_per_s": 300.0, "ramp_s": 0.05, "tail_s": 0.1},
    "series": [
        {"level_g": 1.0, "directions": ["up", "down"], "repeats": 3},
        {"level_g": 2.0, "directions": ["up", "down"], "repeats": 1},
        {"level_g": 5.0, "directions": ["up", "down"], "repeats": 1},
        {"level_g": 10.0, "directions": ["up", "down"], "repeats": 1},
    ],
    "assemblies": {
        "first": {"Fs": 313.0, "KT": 1.02e6, "chi": -0.65, "beta": 0.004, "k": 6.12e5, "zeta_v": 0.0015},
        "reassembly": {"Fs": 274.0, "KT": 0.90e6, "chi": -0.61, "beta": 0.025, "k": 8.56e5, "zeta_v": 0.0017},
    },
    "measurement": {"noise_fraction": 0.003, "dc_offset_g": 0.005, "bits": 24,
                    "full_scale_g": {"base": "auto", "response": "auto"}, "oversample": 2,
                    "antialias_order": 8, "antialias_cutoff": 0.42, "ripple": 0.01, "distortion": [0.003, 0.002]},
    "effect": {"name": "none", "params": {}},
    "rig": {"reference": "base", "shaker": {}},
}
JOINT_KEYS = ("Fs", "KT", "chi", "beta")
RIG_LEVEL = {"base": "level_g", "force": "level_V", "voltage": "level_V"}  # series key per rig reference


def _merge(base: dict, over: dict) -> dict:
    out = copy.deepcopy(base)
    for k, v in over.items():
        if k in out and isinstance(out[k], dict) and isinstance(v, dict) and k != "assemblies":
            out[k] = _merge(out[k], v)
        else:
            out[k] = copy.deepcopy(v)
    return out


def _number(value, where: str, what: str) -> float:
    """A float from a spec value; YAML 1.1 reads '1.02e6' as text, which is fine here."""
    try:
        out = float(value)
    except (TypeError, ValueError):
        raise ValueError(f"{where}: {what} must be a number, got {value!r}.") from None
    if not (out == out and abs(out) != float("inf")):
        raise ValueError(f"{where}: {what} must be finite, got {value!r}.")
    return out


def _coerce(s: dict, where: str) -> None:
    for key in ("sample_rate_hz", "slug_weight_lbf"):
        s[key] = _number(s[key], where, key)
    for key in ("f_start_hz", "f_stop_hz", "rate_hz_per_s", "ramp_s", "tail_s"):
        s["sweep"][key] = _number(s["sweep"][key], where, f"sweep.{key}")
    for name, a in s["assemblies"].items():
        if not isinstance(a, dict):
            raise ValueError(f"{where}: assembly {name!r} must map Fs, KT, chi, beta, k, zeta_v to numbers.")
        for key in a:
            a[key] = _number(a[key], where, f"assemblies.{name}.{key}")
    level = RIG_LEVEL.get(s["rig"].get("reference"), "level_g")
    for item in s["series"]:
        if level not in item:
            raise ValueError(f"{where}: series item {item} needs {level} for a rig with reference "
                             f"{s['rig'].get('reference')!r}.")
        item[level] = _number(item.get(level), where, f"series {level}")
        item["repeats"] = int(_number(item.get("repeats", 1), where, "series repeats"))
    sh = s["rig"].get("shaker") or {}
    for key in sh:
        sh[key] = _number(sh[key], where, f"rig.shaker.{key}")
    m = s["measurement"]
    for key in ("noise_fraction", "dc_offset_g", "antialias_cutoff", "ripple"):
        m[key] = _number(m[key], where, f"measurement.{key}")
    for key in ("bits", "oversample", "antialias_order"):
        m[key] = int(_number(m[key], where, f"measurement.{key}"))
    m["distortion"] = [_number(v, where, "measurement.distortion") for v in m["distortion"]]
    for ch, v in m["full_scale_g"].items():
        m["full_scale_g"][ch] = v if v == "auto" else _number(v, where, f"measurement.full_scale_g.{ch}")


def _parse(path: Path):
    """The YAML or JSON document in `path`; a syntax error is one sentence naming the line."""
    try:
        text = path.read_text()
        return json.loads(text) if path.suffix == ".json" else yaml.safe_load(text)
    except json.JSONDecodeError as exc:
        raise ValueError(f"{path}: not valid JSON at line {exc.lineno}, column {exc.colno} ({exc.msg}); "
                         "fix the syntax there.") from None
    except yaml.YAMLError as exc:
        mark = getattr(exc, "problem_mark", None)
        at = f" at line {mark.line + 1}, column {mark.column + 1}" if mark is not None else ""
        problem = getattr(exc, "problem", None) or type(exc).__name__
        raise ValueError(f"{path}: not valid YAML{at} ({problem}); fix the syntax there "
                         "(indent nested keys by spaces, quote text holding ':' or '#').") from None
    except (OSError, UnicodeDecodeError) as exc:
        raise ValueError(f"{path}: cannot be read ({exc}); give a readable YAML or JSON text file.") from None


SHAPES = {"sweep": dict, "series": list, "assemblies": dict, "measurement": dict, "effect": dict}


def _check_shapes(s: dict, where: str) -> None:
    """One sentence when a section has the wrong kind (a mapping for a list, a number for a mapping, ...)."""
    word = {dict: "a mapping of keys", list: "a list"}
    for key, kind in SHAPES.items():
        if not isinstance(s[key], kind):
            hint = " of {level_g, directions, repeats} items, each starting with '- '" if key == "series" else ""
            raise ValueError(f"{where}: {key} must be {word[kind]}{hint}, got {type(s[key]).__name__} "
                             f"{s[key]!r:.60}; write it as in jointcal.synth.spec's DEFAULT_SPEC.")
    for i, item in enumerate(s["series"]):
        if not isinstance(item, dict):
            raise ValueError(f"{where}: series item {i + 1} must be a mapping {{level_g, directions, repeats}}, "
                             f"got {item!r:.60}; write each item as '- {{level_g: 1.0, directions: [up, down], "
                             "repeats: 1}'.")
    m = s["measurement"]
    if not isinstance(m.get("full_scale_g"), dict) or not isinstance(m.get("distortion"), list):
        raise ValueError(f"{where}: measurement.full_scale_g must be a mapping {{base, response}} and "
                         "measurement.distortion a list [2nd, 3rd]; write them as in DEFAULT_SPEC.")


def load_spec(spec: dict | str | os.PathLike) -> dict:
    """Complete a spec with the defaults and validate it (one clear error per problem)."""
    spec, where, root = _read_spec(spec)
    unknown = set(spec) - set(DEFAULT_SPEC) - {"seed", "effect_file", "first_sequence"}
    if unknown:
        raise ValueError(f"{where}: unknown key(s) {sorted(unknown)}; valid keys are {sorted(DEFAULT_SPEC)} + seed, "
                         "first_sequence.")
    if "seed" not in spec or not isinstance(spec["seed"], int):
        raise ValueError(f"{where}: 'seed' must be given as an integer so the campaign is reproducible.")
    first = spec.get("first_sequence", 1)
    if isinstance(first, bool) or not isinstance(first, int) or first < 1:
        raise ValueError(f"{where}: first_sequence must be an integer >= 1 (the spec's first run's place in the "
                         f"lab's sequence), got {first!r}.")
    s = _merge(DEFAULT_SPEC, spec)
    if "effect_file" in s:
        ef = root / s.pop("effect_file")
        if not ef.is_file():
            raise ValueError(f"{where}: effect_file {ef} not found; fix the path (relative to the spec).")
        s["effect"] = _parse(ef)
    _check_shapes(s, where)
    _check_effects(s, where)
    _coerce(s, where)
    effect_defaults(s["effect"]["name"], s["effect"]["params"])
    _check_values(s, where)
    _check_rig(s, where)
    return s


def _read_spec(spec) -> tuple[dict, str, Path]:
    """The spec mapping, where it came from (for messages) and the folder its relative paths start at."""
    if isinstance(spec, dict):
        return spec, "spec", Path.cwd()
    path = Path(spec)
    if not path.is_file():
        raise ValueError(f"{path}: spec file not found; give the path of a YAML or JSON truth spec.")
    parsed = _parse(path)
    if not isinstance(parsed, dict):
        raise ValueError(f"{path}: a spec must be a mapping of keys (seed, assemblies, ...).")
    return parsed, str(path), path.parent


def _check_effects(s: dict, where: str) -> None:
    """The hidden effect as {name, params}, and a second one (effect.also) checked and completed."""
    also = s["effect"].get("also")  # a second hidden effect at the same time: {name, params}
    s["effect"] = {"name": s["effect"].get("name", "none"), "params": s["effect"].get("params") or {}}
    if also:
        if not isinstance(also, dict) or "name" not in also:
            raise ValueError(f"{where}: effect.also must be a mapping {{name, params}} naming a second effect.")
        s["effect"]["also"] = {"name": also["name"], "params": also.get("params") or {}}
        effect_defaults(also["name"], s["effect"]["also"]["params"])
        if also["name"] == s["effect"]["name"]:
            raise ValueError(f"{where}: effect.also names {also['name']!r} again; hide a different second effect.")


def _check_values(s: dict, where: str) -> None:
    """File format, sweep band against the sample rate, assemblies and the measurement chain."""
    if s["file_format"] not in ("csv", "csv.gz", "mat"):
        raise ValueError(f"{where}: file_format must be csv, csv.gz or mat, got {s['file_format']!r}.")
    sw = s["sweep"]
    if not (sw["rate_hz_per_s"] > 0 and sw["f_start_hz"] > 0 and sw["f_stop_hz"] > 0 and sw["f_start_hz"] != sw["f_stop_hz"]):
        raise ValueError(f"{where}: sweep needs positive f_start_hz != f_stop_hz and rate_hz_per_s > 0, got {sw}.")
    if max(sw["f_start_hz"], sw["f_stop_hz"]) >= 0.45 * s["sample_rate_hz"]:
        raise ValueError(f"{where}: sample_rate_hz {s['sample_rate_hz']} is too low for a band up to "
                         f"{max(sw['f_start_hz'], sw['f_stop_hz'])} Hz; use at least 2.3x the top frequency.")
    for name, a in s["assemblies"].items():
        missing = {"k", "zeta_v"} - set(a)
        joint = [k for k in JOINT_KEYS if k in a]
        if missing or 0 < len(joint) < len(JOINT_KEYS):
            raise ValueError(f"{where}: assembly {name!r} lacks {sorted(missing | (set(JOINT_KEYS) - set(joint)))} "
                             "(give k, zeta_v and all of Fs, KT, chi, beta, or none of these four for a linear structure).")
    m = s["measurement"]
    if not (0 <= m["noise_fraction"] < 1 and m["bits"] >= 8 and int(m["oversample"]) >= 1):
        raise ValueError(f"{where}: measurement needs 0 <= noise_fraction < 1, bits >= 8, oversample >= 1; got {m}.")


def _check_rig(s: dict, where: str) -> None:
    """The rig (reference, shaker, second mode) and the series' levels in the reference's unit."""
    rig = s["rig"]
    if set(rig) - {"reference", "shaker", "second_mode"} or rig.get("reference") not in RIG_LEVEL:
        raise ValueError(f"{where}: rig must be {{reference: base | force | voltage, shaker: {{...}}, "
                         f"second_mode: {{f_hz, zeta, weight_lbf}} (optional)}}, got {rig}.")
    if rig.get("second_mode") is not None:
        if rig["reference"] == "base":
            raise ValueError(f"{where}: rig.second_mode needs a shaker rig (reference force or voltage).")
        try:
            StructureMode(**{k: float(v) for k, v in rig["second_mode"].items()})
        except (TypeError, ValueError, AttributeError) as exc:
            raise ValueError(f"{where}: rig.second_mode: {exc}; its keys are f_hz, zeta, weight_lbf.") from None
    try:
        rig["shaker"] = {**Shaker().__dict__, **(rig.get("shaker") or {})}
        Shaker(**rig["shaker"])
    except TypeError as exc:
        raise ValueError(f"{where}: rig.shaker: {exc}; its keys are {sorted(Shaker().__dict__)}.") from None
    if rig["reference"] != "base" and s["effect"]["name"] == "fixture_flexibility":
        raise ValueError(f"{where}: the fixture_flexibility effect needs rig.reference base (a shaker rig has a "
                         "rigid base).")
    level = RIG_LEVEL[rig["reference"]]
    for item in s["series"]:
        if not (item.get(level, 0) > 0) or any(d not in ("up", "down") for d in item.get("directions", ["up"])):
            raise ValueError(f"{where}: series item {item} needs {level} > 0 and directions among up/down.")
