"""The tracker's settings as a TOML file: read one into a `TrackerConfig`, write the effective one.

Layout (docs/guide.md, "Settings file"): top-level keys are `TrackerConfig` fields, the
`[features]` table holds `FeatureConfig` fields (its `[features.bg_person]` the person
template), and the `[search]` table keyword overrides of `upperpose.SearchConfig`
(`[search.weights]` the cost weights). A field left out keeps its default; TOML has no null,
so a field whose default is None ("the search's own default") is written as a comment.
"""

from __future__ import annotations

import dataclasses
import math
import os
import sys
from collections.abc import Mapping
from typing import Any

from upperpose.exceptions import InputError
from upperpose.features import FeatureConfig
from upperpose.fit.tracker import TrackerConfig

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover - Python 3.10
    import tomli as tomllib

# Fields that are objects, not settings: a ready SearchConfig (its options go to [search]).
_NOT_SETTINGS = ("search",)


def config_from_toml(text: str, source: str = "settings") -> TrackerConfig:
    """The `TrackerConfig` a TOML document describes.

    Raises:
        ValueError: the document is not TOML, names an unknown setting, or gives a value of
            the wrong type (the message names the setting).
    """
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as err:
        raise InputError(f"{source} is not valid TOML: {err}") from None
    return config_from_dict(data, source)


def load_config(path: str | os.PathLike[str]) -> TrackerConfig:
    """Reads a settings file (TOML).

    Raises:
        OSError: the file cannot be read.
        ValueError: see `config_from_toml`.
    """
    with open(path, encoding="utf-8") as f:
        text = f.read()
    return config_from_toml(text, str(path))


def config_from_dict(data: Mapping[str, Any], source: str = "settings") -> TrackerConfig:
    """The `TrackerConfig` of a parsed settings document (see the module's docstring)."""
    data = dict(data)
    features = data.pop("features", None)
    search = data.pop("search", None)
    if search is not None and not isinstance(search, dict):
        raise InputError(f"{source}: [search] must be a table of SearchConfig options")
    fields = _build(TrackerConfig, data, source, skip=_NOT_SETTINGS + ("features", "search_options"))
    if features is not None:
        if not isinstance(features, dict):
            raise InputError(f"{source}: [features] must be a table of FeatureConfig fields")
        fields["features"] = _build_dataclass(FeatureConfig, features, f"{source}: features")
    if search:
        fields["search_options"] = dict(search)
    return TrackerConfig(**fields)


def config_to_dict(config: TrackerConfig) -> dict[str, Any]:
    """The settings of `config` as plain JSON/TOML values (None kept for "the default")."""
    out: dict[str, Any] = {}
    for f in dataclasses.fields(TrackerConfig):
        if f.name in _NOT_SETTINGS + ("features", "search_options"):
            continue
        out[f.name] = _plain(getattr(config, f.name))
    out["features"] = _plain(config.features or FeatureConfig())
    out["search"] = _plain(dict(config.search_options))
    return out


def config_to_toml(config: TrackerConfig) -> str:
    """`config` as a TOML document that `config_from_toml` reads back to an equal config."""
    return _toml_table(config_to_dict(config), ())


def _build(cls: type, data: dict[str, Any], where: str, skip: tuple[str, ...] = ()) -> dict[str, Any]:
    known = {f.name: f for f in dataclasses.fields(cls) if f.name not in skip}
    defaults = cls()
    out: dict[str, Any] = {}
    for key, value in data.items():
        if key not in known:
            allowed = ", ".join(sorted(known))
            raise InputError(f"{where}: unknown setting {key!r} (known: {allowed})")
        out[key] = _coerce(value, getattr(defaults, key), f"{where}: {key}")
    return out


def _build_dataclass(cls: type, data: dict[str, Any], where: str) -> Any:
    return cls(**_build(cls, data, where))


def _coerce(value: Any, default: Any, where: str) -> Any:
    """`value` in the type of the field's default (TOML arrays become tuples, tables dataclasses)."""
    if dataclasses.is_dataclass(default) and not isinstance(default, type):
        if not isinstance(value, dict):
            raise InputError(f"{where} must be a table")
        return _build_dataclass(type(default), value, where)
    if isinstance(default, bool):
        if not isinstance(value, bool):
            raise InputError(f"{where} must be true or false, got {value!r}")
        return value
    if isinstance(default, tuple):
        if not isinstance(value, list):
            raise InputError(f"{where} must be an array, got {value!r}")
        items = tuple(value)
        if default and all(isinstance(v, int) and not isinstance(v, bool) for v in default):
            if not all(isinstance(v, int) and not isinstance(v, bool) for v in items):
                raise InputError(f"{where} must be an array of integers, got {value!r}")
        elif not all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in items):
            raise InputError(f"{where} must be an array of numbers, got {value!r}")
        return items
    if isinstance(default, int):
        if isinstance(value, bool) or not isinstance(value, int):
            raise InputError(f"{where} must be an integer, got {value!r}")
        return value
    if isinstance(default, float):
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            raise InputError(f"{where} must be a number, got {value!r}")
        return float(value)
    if isinstance(default, str) and not isinstance(value, str):
        raise InputError(f"{where} must be a string, got {value!r}")
    if default is None and (isinstance(value, bool) or not isinstance(value, (int, float, str))):
        raise InputError(f"{where} must be a number or a string, got {value!r}")
    return value


def _plain(value: Any) -> Any:
    if dataclasses.is_dataclass(value) and not isinstance(value, type):
        return {f.name: _plain(getattr(value, f.name)) for f in dataclasses.fields(value)}
    if isinstance(value, dict):
        return {str(k): _plain(v) for k, v in value.items()}
    if isinstance(value, (tuple, list)):
        return [_plain(v) for v in value]
    return value


def _toml_value(value: Any) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, int):
        return str(value)
    if isinstance(value, float):
        if not math.isfinite(value):
            return ("-" if value < 0 else "") + ("nan" if math.isnan(value) else "inf")
        return repr(value)
    if isinstance(value, str):
        return '"' + value.replace("\\", "\\\\").replace('"', '\\"') + '"'
    if isinstance(value, list):
        return "[" + ", ".join(_toml_value(v) for v in value) + "]"
    raise InputError(f"cannot write {value!r} as TOML")


def _toml_table(table: dict[str, Any], path: tuple[str, ...]) -> str:
    lines = [f"[{'.'.join(path)}]"] if path else []
    for key, value in table.items():
        if value is None:
            lines.append(f"# {key}: not set (the default applies)")
        elif not isinstance(value, dict):
            lines.append(f"{key} = {_toml_value(value)}")
    for key, value in table.items():
        if isinstance(value, dict):
            lines.append("")
            lines.append(_toml_table(value, (*path, key)).rstrip("\n"))
    return "\n".join(lines) + "\n"


__all__ = ["config_from_dict", "config_from_toml", "config_to_dict", "config_to_toml", "load_config"]
