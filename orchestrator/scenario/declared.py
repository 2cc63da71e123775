"""Declared file formats: one declaration per format (scenario, campaign, arena, design file) drives both
the checks ftcsim makes when it reads a file and the JSON Schema (draft 2020-12) it publishes for
editors (``ftcsim schema NAME``, ``orchestrator/schemas/``, docs/file-formats.md).

A declaration is a tree of rules. :class:`Table` holds named keys (``fields``), or keys the user names
(``extra``: instances, plants, parameters); :class:`Union` is a table whose keys depend on a tag (a
source's ``type``, a dispersion's ``distribution``); :class:`ListOf` an array; the leaves are
:class:`Number`, :class:`Whole`, :class:`Seconds`, :class:`Text`, :class:`Name`, :class:`Choice`,
:class:`Flag`, :class:`Values` (a number or an array of numbers) and :class:`Anything`.
``rule.check(src, key, x)`` returns the value checked (numbers as float or int, defaults filled in)
or raises the one ``InputError(file, key, problem)``: numbers go through the one numeric gate
(:func:`orchestrator.scenario.values.number`), an unknown key or value names the closest known one.
``rule.schema()`` is the same rule in JSON Schema.

What a schema cannot say (a reference to an instance of the file, a value against an FMU's
declaration, one key against another) stays in the loaders; a :class:`Format` lists those checks in
``elsewhere``, which its schema's description repeats. The schemas keep to what Taplo 0.9 (the engine
of VS Code's Even Better TOML) evaluates: no ``$ref`` beside other keywords, no ``prefixItems`` or
``dependentRequired`` (``if``/``then`` instead).
"""
from __future__ import annotations

import copy
import json
import re
import sys
from dataclasses import dataclass, field

from orchestrator.common.errors import InputError
from orchestrator.common.outputs import safe_name
from orchestrator.common.watchdog import MAX_SECONDS
from orchestrator.scenario.values import article, hint, is_number, number, seconds, short, unknown_key, whole

DRAFT = "https://json-schema.org/draft/2020-12/schema"
INT64_MAX = 2**63 - 1
MISSING = object()  # no default
BIG = sys.float_info.max
FINITE = {  # $defs/finite: every number of every format
    "type": "number", "minimum": -BIG, "maximum": BIG, "not": {"minimum": 1, "maximum": 0},
    "description": "A finite number. Infinities lie beyond the bounds. NaN compares false with every bound, so it alone "
                   "passes the test of the `not` clause (no number is both >= 1 and <= 0): NaN is refused too. Taplo "
                   "reads TOML's nan and inf as null, which is not a number."}


def join(key: str, name) -> str:
    return f"{key}.{name}" if key else str(name)


class Rule:
    """One value's rule: :meth:`check` a value, :meth:`schema` it."""

    description: str = ""
    default: object = MISSING
    missing: str = ""  # said after "missing" when the key is required and absent

    def check(self, src, key, x):
        raise NotImplementedError

    def rule(self) -> dict:
        raise NotImplementedError

    def schema(self) -> dict:
        s = {"description": self.description} if self.description else {}
        s.update(self.rule())
        if self.default is not MISSING:
            s["default"] = self.default
        return s


def _finite(**bounds) -> dict:
    return {"allOf": [{"$ref": "#/$defs/finite"}], **{k: v for k, v in bounds.items() if v is not None}}


@dataclass(frozen=True)
class Number(Rule):
    """A finite real number (numpy scalars too, never a boolean): > 0 with ``positive``, >= ``lower``,
    <= ``upper``, < ``below``."""

    description: str = ""
    positive: bool = False
    lower: float | None = None
    upper: float | None = None
    below: float | None = None
    default: object = MISSING
    missing: str = ""

    def check(self, src, key, x) -> float:
        x = number(src, key, x)  # the one numeric gate: type and finiteness
        low = 0.0 if self.positive else self.lower
        high = self.upper if self.below is None else self.below
        too_low = low is not None and (x <= low if self.positive else x < low)
        too_high = high is not None and (x >= high if self.below is not None else x > high)
        if not (too_low or too_high):
            return x
        if low is not None and high is not None:
            if self.positive and self.below is not None:
                raise InputError(src, key, f"must lie strictly between {low:g} and {high:g}, got {x:g}")
            span = f"{'(' if self.positive else '['}{low:g}, {high:g}{')' if self.below is not None else ']'}"
            raise InputError(src, key, f"must be in {span}, got {x:g}")
        if too_low:
            raise InputError(src, key, f"must be {'>' if self.positive else '>='} {low:g}, got {x:g}")
        raise InputError(src, key, f"must be {'<' if self.below is not None else '<='} {high:g}, got {x:g}")

    def rule(self) -> dict:
        return _finite(exclusiveMinimum=0 if self.positive else None, minimum=self.lower, maximum=self.upper,
                       exclusiveMaximum=self.below)


@dataclass(frozen=True)
class Whole(Rule):
    """An integer (not a boolean, not a float) in [``lower``, ``upper``]."""

    description: str = ""
    lower: int | None = None
    upper: int | None = None
    default: object = MISSING
    missing: str = ""

    def check(self, src, key, x) -> int:
        x = whole(src, key, x)
        lo, hi = self.lower, self.upper
        if (lo is None or x >= lo) and (hi is None or x <= hi):
            return x
        got = x if abs(x) < 10**20 else f"a number of {len(str(abs(x)))} digits"
        if hi is None or (hi >= INT64_MAX and x < lo):
            raise InputError(src, key, f"must be >= {lo}, got {got}")
        if lo is None:
            raise InputError(src, key, f"must be <= {hi}, got {got}")
        span = "at most 2**63 - 1" if hi >= INT64_MAX else f"in {lo}..{hi}"
        raise InputError(src, key, f"must be {span}, got {got}")

    def rule(self) -> dict:
        return {"type": "integer", **({"minimum": self.lower} if self.lower is not None else {}),
                **({"maximum": self.upper} if self.upper is not None else {})}


@dataclass(frozen=True)
class Seconds(Rule):
    """A duration of wall time (s): > 0 and at most a year (:func:`orchestrator.scenario.values.seconds`)."""

    description: str = ""
    default: object = MISSING

    def check(self, src, key, x) -> float:
        return seconds(src, key, x)

    def rule(self) -> dict:
        return _finite(exclusiveMinimum=0, maximum=MAX_SECONDS)


@dataclass(frozen=True)
class Text(Rule):
    """A string: non-empty unless ``empty``; matching ``pattern`` (whole) if given, else ``rule_text``
    says why not; ``what``: what the message says was expected instead of another type."""

    description: str = ""
    empty: bool = False
    what: str = ""
    pattern: str | None = None
    rule_text: str = ""
    max_length: int | None = None
    examples: tuple = ()
    default: object = MISSING
    missing: str = ""

    def check(self, src, key, x) -> str:
        if not isinstance(x, str) or not (x or self.empty):
            what = self.what or f"a {'' if self.empty else 'non-empty '}string"
            raise InputError(src, key, f"expected {what}, got {short(x)}")
        if (self.pattern and not re.fullmatch(self.pattern, x)) or (self.max_length and len(x) > self.max_length):
            raise InputError(src, key, f"{short(x)} {self.rule_text}")
        return x

    def rule(self) -> dict:
        s = {"type": "string"} if self.empty else {"type": "string", "minLength": 1}
        if self.pattern:
            s["pattern"] = f"^{self.pattern}$"
        if self.max_length:
            s["maxLength"] = self.max_length
        if self.examples:
            s["examples"] = list(self.examples)
        return s


@dataclass(frozen=True)
class Name(Rule):
    """A name that becomes one file or folder name (:func:`orchestrator.common.outputs.safe_name`)."""

    description: str = ""
    missing: str = ""

    def check(self, src, key, x) -> str:
        return safe_name(x, src, key)

    def rule(self) -> dict:  # safe_name's rule: no separator, no '..' (a '.' is followed by another character)
        return {"type": "string", "pattern": r"^[A-Za-z0-9_](\.?[A-Za-z0-9_+-])*\.?$", "maxLength": 100}


@dataclass(frozen=True)
class Choice(Rule):
    """One of ``values`` (strings). ``what`` names the kind in the message (``"unknown mode 'x'"``; ``""``:
    ``"unknown 'x'"``); without it the message lists the values (``"must be 'a' or 'b', not 'x'"``)."""

    values: tuple
    description: str = ""
    what: str | None = None
    default: object = MISSING
    missing: str = ""

    def check(self, src, key, x) -> str:
        if isinstance(x, str) and x in self.values:
            return x
        known = ", ".join(self.values)
        close = hint(x, self.values) if isinstance(x, str) else ""
        if self.what is None:
            alts = " or ".join(map(repr, self.values)) if len(self.values) == 2 else f"one of {known}"
            raise InputError(src, key, f"must be {alts}, not {short(x)}{close}")
        kind = f"{self.what} " if self.what else ""
        if not isinstance(x, str):
            raise InputError(src, key, f"unknown {kind}{short(x)}: expected one of {known} (a string), got "
                                       f"{type(x).__name__}")
        raise InputError(src, key, f"unknown {kind}{short(x)}{close or f' (known: {known})'}")

    def rule(self) -> dict:
        return {"enum": list(self.values)}


@dataclass(frozen=True)
class Flag(Rule):
    description: str = ""
    default: object = MISSING

    def check(self, src, key, x) -> bool:
        if not isinstance(x, bool):
            raise InputError(src, key, f"expected true or false, got {short(x)}")
        return x

    def rule(self) -> dict:
        return {"type": "boolean"}


@dataclass(frozen=True)
class Values(Rule):
    """A number, or an array of numbers up to ``depth`` levels (a vector, a matrix, a rule tensor);
    the shape is checked where it is known (against the FMU's parameter). Every element is named by
    the key itself."""

    description: str = ""
    depth: int = 4
    missing: str = ""

    def check(self, src, key, x):
        stack = [(x, 0)]
        while stack:
            v, d = stack.pop()
            if isinstance(v, list):
                if d >= self.depth:
                    raise InputError(src, key, f"expected a number or an array of at most {self.depth} dimensions")
                stack.extend((e, d + 1) for e in v)
            elif d and not is_number(v):
                raise InputError(src, key, f"expected a number, got {type(v).__name__} {short(v)}: an array holds "
                                           "numbers only")
            else:
                number(src, key, v)
        return x

    def rule(self) -> dict:
        return {"allOf": [{"$ref": f"#/$defs/values{self.depth}"}]}

    @staticmethod
    def definition(depth: int) -> dict:
        """``$defs/valuesN``: a number or arrays of numbers nested at most N deep."""
        s = _finite()
        for _ in range(depth):
            s = {"anyOf": [_finite(), {"type": "array", "items": s}]}
        return {"description": f"a number, or an array of numbers nested at most {depth} deep", **s}


@dataclass(frozen=True)
class Interval(Rule):
    """``[low, high]``: two finite numbers, high >= low (> with ``strict``), both within [``lower``,
    ``upper``]; ``what`` is what the message says was expected."""

    description: str = ""
    what: str = "[low, high]"
    lower: float | None = None
    upper: float | None = None
    strict: bool = False
    default: object = MISSING
    missing: str = ""

    def check(self, src, key, x) -> list:
        if not (isinstance(x, list) and len(x) == 2):
            raise InputError(src, key, f"expected {self.what}, got {short(x)}")
        a, b = (number(src, key, v) for v in x)
        if (self.lower is not None and a < self.lower) or (self.upper is not None and b > self.upper):
            raise InputError(src, key, f"must lie in [{self.lower}, {'inf' if self.upper is None else self.upper}], "
                                       f"got [{a}, {b}]")
        if b < a or (self.strict and b == a):
            raise InputError(src, key, f"'to' ({b:g}) must be after 'from' ({a:g})" if self.strict else f"high {b} < low {a}")
        return [a, b]

    def rule(self) -> dict:
        return {"type": "array", "items": _finite(minimum=self.lower, maximum=self.upper), "minItems": 2, "maxItems": 2}


@dataclass(frozen=True)
class Anything(Rule):
    """Any value (a record a program wrote and ftcsim does not read)."""

    description: str = ""

    def check(self, src, key, x):
        return x

    def rule(self) -> dict:
        return {}


@dataclass(frozen=True)
class Either(Rule):
    """The first of ``rules`` the value meets (the message is the first rule's)."""

    rules: tuple
    description: str = ""

    def check(self, src, key, x):
        first = None
        for rule in self.rules:
            try:
                return rule.check(src, key, x)
            except InputError as e:
                first = first or e
        raise first

    def rule(self) -> dict:
        return {"anyOf": [r.schema() for r in self.rules]}


@dataclass(frozen=True)
class ListOf(Rule):
    """An array of ``item``s: at least ``min_items``, at most ``max_items``; ``single``: a lone item is
    a list of one; ``unique``: no value twice; ``index``: elements named ``key[j]`` (else ``key``).
    ``what`` is what the message says was expected."""

    item: Rule
    description: str = ""
    what: str = "a list"
    min_items: int = 0
    max_items: int | None = None
    single: bool = False
    unique: bool = False
    index: bool = True
    default: object = MISSING
    missing: str = ""

    def check(self, src, key, x) -> list:
        if self.single and not isinstance(x, list):
            x = [x]
        if not isinstance(x, list) or len(x) < self.min_items or (self.max_items is not None and len(x) > self.max_items):
            raise InputError(src, key, f"expected {self.what}, got {short(x)}")
        out = [self.item.check(src, f"{key}[{j}]" if self.index else key, v) for j, v in enumerate(x)]
        if self.unique and len({repr(v) for v in out}) != len(out):
            raise InputError(src, key, "lists a value twice")
        return out

    def rule(self) -> dict:
        s = {"type": "array", "items": self.item.schema()}
        if self.min_items:
            s["minItems"] = self.min_items
        if self.max_items is not None:
            s["maxItems"] = self.max_items
        if self.unique:
            s["uniqueItems"] = True
        return {"anyOf": [self.item.schema(), s]} if self.single else s


@dataclass(frozen=True)
class Table(Rule):
    """A table of the keys ``fields`` (unknown keys refused with the closest one suggested), or, with
    ``extra``, of keys the user names (each checked by ``names``, its value by ``extra``).

    ``required``: keys every file must give; ``complete``: keys required once ``extends`` is resolved
    (a file that extends another may leave them to its base); ``only_with``: {key: the key it needs};
    ``min_items``: at least that many keys, else ``empty`` is the message."""

    fields: dict = field(default_factory=dict)
    description: str = ""
    required: tuple = ()
    complete: tuple = ()
    extra: Rule | None = None
    names: Rule | None = None
    only_with: dict = field(default_factory=dict)
    min_items: int = 0
    empty: str = ""
    default: object = MISSING
    missing: str = ""

    def check(self, src, key, x) -> dict:
        if not isinstance(x, dict):
            raise InputError(src, key, f"expected a table, got {type(x).__name__}")
        for k in x:
            if k in self.fields:
                continue
            if self.extra is None:
                raise unknown_key(src, key, k, list(self.fields))
            if self.names is not None:
                self.names.check(src, join(key, k), k)
        for k in self.required + self.complete:
            if k not in x:
                raise InputError(src, join(key, k), "missing" + self.fields[k].missing)
        if len(x) < self.min_items:
            raise InputError(src, key, self.empty or f"expected at least {self.min_items} keys")
        for k, need in self.only_with.items():
            if k in x and need not in x:
                raise InputError(src, join(key, k), f"applies only with {article(need)}")
        out = {k: self.fields.get(k, self.extra).check(src, join(key, k), v) for k, v in x.items()}
        for k, f in self.fields.items():  # defaults; an absent table gets its own defaults
            if k not in out and f.default is not MISSING:
                out[k] = f.check(src, join(key, k), {}) if isinstance(f, Table) else copy.deepcopy(f.default)
        return out

    def rule(self) -> dict:
        s = {"type": "object"}
        if self.fields:
            s["properties"] = {k: f.schema() for k, f in self.fields.items()}
        if self.required:
            s["required"] = list(self.required)
        if self.names is not None:
            s["propertyNames"] = self.names.rule()
        s["additionalProperties"] = False if self.extra is None else self.extra.schema()
        if self.min_items:
            s["minProperties"] = self.min_items
        if self.only_with:
            s["allOf"] = [{"if": {"required": [k]}, "then": {"required": [need]}} for k, need in self.only_with.items()]
        return s

    def completion(self) -> dict | None:
        """The ``required`` of the keys left to a base file (``complete``), nested as the tables are."""
        s = {"required": list(self.complete)} if self.complete else {}
        inner = {k: c for k, f in self.fields.items() if isinstance(f, Table) and (c := f.completion())}
        if inner:
            s["properties"] = inner
        if isinstance(self.extra, Table) and (c := self.extra.completion()):
            s["additionalProperties"] = c
        return s or None


@dataclass(frozen=True)
class Union(Rule):
    """A table whose keys depend on its ``tag`` (``variants``: tag value -> :class:`Table`, each
    declaring the tag itself); ``default``: the variant of a table without the tag."""

    tag: str
    variants: dict
    description: str = ""
    what: str = "type"
    default_variant: str | None = None

    def check(self, src, key, x) -> dict:
        if not isinstance(x, dict):
            raise InputError(src, key, f"expected a table, got {type(x).__name__}")
        t = x.get(self.tag, self.default_variant)
        if t is None:
            raise InputError(src, join(key, self.tag), f"missing (one of {', '.join(self.variants)})")
        Choice(tuple(self.variants), what=self.what).check(src, join(key, self.tag), t)
        return self.variants[t].check(src, key, x)

    def rule(self) -> dict:
        s = {"type": "object", "properties": {self.tag: {"enum": list(self.variants)}}}
        if self.default_variant is None:
            s["required"] = [self.tag]
        s["allOf"] = [{"if": {"properties": {self.tag: {"const": v}}, **({} if v == self.default_variant else
                                                                       {"required": [self.tag]})},
                       "then": t.schema()} for v, t in self.variants.items()]
        return s


@dataclass(frozen=True)
class Format:
    """A file format: its root :class:`Table`, the ``(section, key)`` of its ``extends`` if it has one,
    and ``elsewhere``: the checks ftcsim makes that the schema cannot (cross-field rules, references
    into the file or into FMUs), each a sentence."""

    name: str
    title: str
    root: Table
    description: str
    extends: tuple | None = None
    elsewhere: tuple = ()
    kind: str = "TOML"

    def check(self, src, doc: dict) -> dict:
        """The document checked against the declaration (every key, type and range; defaults filled in)."""
        return self.root.check(src, "", doc)

    def json_schema(self) -> dict:
        text = self.description
        if self.elsewhere:
            text += "\n\nChecked by ftcsim, not by this schema:\n" + "\n".join(f"- {e}" for e in self.elsewhere)
        s = {"$schema": DRAFT, "title": self.title, "description": text,
             "$comment": f"Generated from ftcsim's declaration of the {self.name} format by `ftcsim schema {self.name}`; "
                         "do not edit.",
             "$defs": {"finite": FINITE}, **self.root.rule()}
        for depth in sorted({int(n) for n in re.findall(r"#/\$defs/values(\d+)", json.dumps(s))}):
            s["$defs"][f"values{depth}"] = Values.definition(depth)
        completion = self.root.completion()
        if completion:
            if self.extends is None:
                raise ValueError(f"{self.name}: keys left to a base file, but the format has no extends")
            section, key = self.extends
            s["if"] = {"required": [section], "properties": {section: {"required": [key]}}}
            s["else"] = completion
        return s
