"""Parse-time helpers of the Snakemake workflow: what a stage's code is, and config keys users mistype.

`stage_sources` follows a stage script's ``jointcal`` imports through the package with
`ast` (every ``import``/``from ... import`` statement, at any depth of the file, relative
imports resolved, each parent package's ``__init__`` included as Python runs it), so a
module added later is never forgotten; `stage_hash` is the SHA-256 of those files. The
workflow passes the hash as a rule's ``params`` so that editing ``jointcal.measure.modal`` reruns
the modal rules and their descendants, and nothing upstream. Not seen: imports built at
run time (``importlib``), third-party packages, and data files read by the package.

`campaign_index` and `pending_outputs` (in `jointcal._campaign_index`, re-exported here): the
campaign's manifest read once for the DAG's names, and the files Snakemake's ``--summary`` still
plans to remake.

`config_problem` checks a merged config against the workflow's JSON schema before
Snakemake's own ``validate`` (whose message is a dump of the schema): an unknown key gets
one line naming it and the nearest valid key, and a value the schema rejects one line naming
the key and the reason; a value Snakemake's ``--config`` left as text
in a nested section is converted to the schema's type when it parses as one.
"""
from __future__ import annotations

import ast
import difflib
import functools
import hashlib
import os
from collections.abc import Iterable, Mapping, MutableMapping
from pathlib import Path
from typing import Any

import yaml

from ._campaign_index import (CampaignIndex, campaign_index, modal_units, pending_outputs,  # noqa: F401 (re-exported)
                              unit_labels, unit_of, unit_outputs, unit_table)

__all__ = ["stage_sources", "stage_hash", "stage_hashes", "CampaignIndex", "campaign_index", "modal_units", "unit_of", "unit_labels", "unit_table", "unit_outputs", "pending_outputs",
           "config_problem"]

_PACKAGE = "jointcal"
_ROOT = Path(__file__).resolve().parent  # the jointcal package being imported


def _module_file(name: str) -> Path | None:
    """File of module `name` (``jointcal.a.b``) inside the package, or None."""
    parts = name.split(".")[1:]
    base = _ROOT.joinpath(*parts)
    for f in (base / "__init__.py", base.with_suffix(".py")):
        if f.is_file():
            return f
    return None


def _module_name(f: Path) -> tuple[str, bool] | None:
    """Dotted name of a file inside the package and whether it is a package ``__init__``."""
    try:
        rel = f.resolve().relative_to(_ROOT)
    except ValueError:
        return None
    parts = [_PACKAGE, *rel.with_suffix("").parts]
    if parts[-1] == "__init__":
        return ".".join(parts[:-1]), True
    return ".".join(parts), False


def _statements(body: list[ast.stmt]):
    """Every statement of a block and of the blocks nested in it (function and class bodies, branches, loops,
    ``try`` handlers, ``with`` and ``match`` blocks): where an import statement can stand, without walking the
    expressions, which hold none."""
    for node in body:
        yield node
        for field in ("body", "orelse", "finalbody"):
            sub = getattr(node, field, None)
            if isinstance(sub, list):
                yield from _statements(sub)
        for part in (*getattr(node, "handlers", ()), *getattr(node, "cases", ())):
            yield from _statements(part.body)


def _imported(tree: ast.Module, here: tuple[str, bool] | None) -> set[str]:
    """Dotted names a module's import statements may load (a ``from`` import's names may be modules)."""
    names: set[str] = set()
    for node in _statements(tree.body):
        if isinstance(node, ast.Import):
            names.update(a.name for a in node.names)
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                if here is None:
                    continue
                pkg = here[0] if here[1] else here[0].rpartition(".")[0]
                pkg = ".".join(pkg.split(".")[: len(pkg.split(".")) - (node.level - 1)])
                base = f"{pkg}.{node.module}" if node.module else pkg
            else:
                base = node.module or ""
            names.add(base)
            names.update(f"{base}.{a.name}" for a in node.names)
    return {n for n in names if n == _PACKAGE or n.startswith(_PACKAGE + ".")}


def stage_sources(script: str | os.PathLike[str]) -> list[Path]:
    """The script and every ``jointcal`` source file it imports, recursively.

    Parameters
    ----------
    script : path-like
        A workflow script (``workflow/scripts/<stage>.py``) or a module of the package.

    Returns
    -------
    list of Path
        The script first, then the package files in sorted order.
    """
    return _sources([script])[0]


def _sources(scripts: Iterable[str | os.PathLike[str]]) -> list[list[Path]]:
    """`stage_sources` of each script, the package's files read, parsed and looked up once for all of them (the
    stages share most modules: a workflow's parse hashes ~17)."""
    files: dict[str, Path | None] = {}  # module name -> its file
    direct: dict[Path, set[Path]] = {}  # file -> the package files its import statements run

    def imports(f: Path) -> set[Path]:
        if f not in direct:
            out: set[Path] = set()
            for name in _imports_of(str(f), f.read_bytes(), _module_name(f)):
                parts = name.split(".")
                for i in range(1, len(parts) + 1):  # importing a.b.c runs a/__init__ and a/b/__init__ first
                    prefix = ".".join(parts[:i])
                    if prefix not in files:
                        files[prefix] = _module_file(prefix)
                    if files[prefix] is not None:
                        out.add(files[prefix])  # type: ignore[arg-type]
            direct[f] = out
        return direct[f]

    result = []
    for script in scripts:
        script = Path(script).resolve()
        seen: set[Path] = set()
        todo = [script]
        while todo:
            f = todo.pop()
            if f not in seen:
                seen.add(f)
                todo.extend(imports(f) - seen)
        result.append([script, *sorted(seen - {script})])
    return result


@functools.lru_cache(maxsize=None)
def _imports_of(filename: str, text: bytes, here: tuple[str, bool] | None) -> frozenset[str]:
    """`_imported` of a file's text, parsed once per process (a workflow's parse hashes ~17 stages, which share
    most modules; the key is the text itself, so an edited file is parsed again)."""
    return frozenset(_imported(ast.parse(text, filename=filename), here))


def stage_hash(script: str | os.PathLike[str]) -> str:
    """SHA-256 (hex, first 16 digits) of `stage_sources` (paths inside the package and contents)."""
    return stage_hashes([script])[0]


def stage_hashes(scripts: Iterable[str | os.PathLike[str]]) -> list[str]:
    """`stage_hash` of each script, in order: the files they share read once (a workflow's parse hashes every
    stage; measured 1.05 -> 0.63 s for the 17 scripts, most of the rest their parse)."""
    texts: dict[Path, bytes] = {}
    out = []
    for sources in _sources(scripts):
        h = hashlib.sha256()
        for f in sources:
            if f not in texts:
                texts[f] = f.read_bytes()
            rel = f.relative_to(_ROOT).as_posix() if f.is_relative_to(_ROOT) else f.name
            h.update(rel.encode() + b"\0" + texts[f] + b"\0")
        out.append(h.hexdigest()[:16])
    return out


def _resolve(schema: Mapping[str, Any], root: Mapping[str, Any]) -> Mapping[str, Any]:
    ref = schema.get("$ref")
    if isinstance(ref, str) and ref.startswith("#/"):
        node: Any = root
        for part in ref[2:].split("/"):
            node = node[part]
        return {**node, **{k: v for k, v in schema.items() if k != "$ref"}}
    return schema


_TYPES = {"number": (int, float), "integer": (int,), "boolean": (bool,), "array": (list,), "object": (dict,)}
_NULL_TEXT = ("null", "none", "~", "")
_UNPARSED = object()


def _parse(text: str, want: str) -> Any:
    """`text` read as JSON-schema type `want`, or `_UNPARSED`."""
    if want == "null":
        return None if text.strip().lower() in _NULL_TEXT else _UNPARSED
    if want not in _TYPES:
        return _UNPARSED
    try:  # float() reads 1e-3, which YAML 1.1 (PyYAML) leaves as text
        parsed = int(text) if want == "integer" else float(text) if want == "number" else yaml.safe_load(text)
    except (ValueError, yaml.YAMLError):
        return _UNPARSED
    ok = isinstance(parsed, _TYPES[want]) and not (want != "boolean" and isinstance(parsed, bool))
    return parsed if ok else _UNPARSED


def _coerce(value: Any, schema: Mapping[str, Any], root: Mapping[str, Any]) -> Any:
    """A text value (as ``--config`` leaves nested ones) parsed to the schema's type, if it parses as one.

    The schema's ``type`` may be one name or a list of them (``["number", "null"]``), tried in order;
    an array's items are converted by the items' own schema.
    """
    want = schema.get("type")
    wants = [want] if isinstance(want, str) else [w for w in (want or []) if isinstance(w, str)]
    if isinstance(value, str):
        for w in wants:
            parsed = _parse(value, w)
            if parsed is not _UNPARSED:
                value = parsed
                break
        else:
            return value
    if isinstance(value, list) and "array" in wants and isinstance(schema.get("items"), Mapping):
        items = _resolve(schema["items"], root)
        return [_coerce(v, items, root) for v in value]
    return value


def config_problem(config: MutableMapping[str, Any], schema_file: str | os.PathLike[str]) -> str | None:
    """Check config keys against the schema, recursively; convert nested text values in place.

    Parameters
    ----------
    config : dict
        Snakemake's merged config (edited in place: text values of nested sections that
        parse as the schema's number, integer, boolean or array become that).
    schema_file : path-like
        The workflow's JSON schema (YAML).

    Returns
    -------
    str or None
        One sentence naming the first unknown key and the nearest valid one, or else
        the first value the schema rejects, or None.
    """
    root = yaml.safe_load(Path(schema_file).read_text())

    def walk(cfg: MutableMapping[str, Any], schema: Mapping[str, Any], path: str) -> str | None:
        props = schema.get("properties", {})
        for key in list(cfg):
            where = f"{path}{key}"
            if key not in props:
                if schema.get("additionalProperties", True) is not False:
                    continue
                near = difflib.get_close_matches(str(key), list(props), n=1, cutoff=0.5)
                hint = (f"did you mean '{path}{near[0]}'?" if near else
                        f"the keys here are {', '.join(props)}.")
                return (f"config key '{where}' is not a setting of this workflow; {hint} "
                        f"(all settings: workflow/config/config.yaml)")
            sub = _resolve(props[key], root)
            cfg[key] = value = _coerce(cfg[key], sub, root)
            if isinstance(value, MutableMapping) and "properties" in sub:
                found = walk(value, sub, f"{where}.")
                if found:
                    return found
        return None

    found = walk(config, root, "")
    if found:
        return found
    from jsonschema import Draft202012Validator  # Snakemake's own validator (a dependency of snakemake)
    from jsonschema.exceptions import best_match

    err = best_match(Draft202012Validator(root).iter_errors(config))
    if err is None:
        return None
    where = ".".join(map(str, err.absolute_path)) or "(top level)"
    msg = f"config '{where}': {err.message}"
    if err.validator == "type" and isinstance(err.instance, str):
        msg += ("; a nested section given with --config is read as text: put it in a YAML file and pass "
                "--configfile my.yaml")
    return msg + " (all settings: workflow/config/config.yaml)"
