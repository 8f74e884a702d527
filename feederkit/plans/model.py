"""The plan as one immutable value: parts, sensor, a tree of steps, results and statistics.

A plan (sections 4, 6 and 8.5 of Akella & Mason 1999; the file is design.md's
``feederkit-plan``) is a tree: each :class:`Step` rotates the part by ``action_deg`` within its
overlap range ``action_deg ± margin_deg`` (none at the root, the first alignment from an
unknown orientation), lets it align on the fence and reads its diameter; each
:class:`Branch` is followed when its closed reading interval holds the reading; a
:class:`Leaf` lists the (part, landing, state) triples the part may then be in, every one a
correct answer, and a reject leaf (``reject``) lists landings the next station cannot take
(design.md, "Landings"). The tree may share subtrees (a DAG: the file's ``"nodes"`` table);
every walk here visits each distinct node once, so a plan with astronomically many paths
costs its number of distinct nodes.

Only :mod:`feederkit.plans.fileformat` (from a planner's result) and
:mod:`feederkit.plans.readplan` (from a file, its text or a dict) make a :class:`Plan`, and
only fileformat and :mod:`feederkit.plans.writeplan` write one; everything else reads it.
Every value here is a frozen dataclass; a part's push function (section 3.1) is rebuilt from
the hull and COM the plan records, by :func:`push_function_of`, an explicit cache keyed by the
part.
"""

from __future__ import annotations

import bisect
import functools
import math
from collections.abc import Iterable, Iterator, Sequence
from dataclasses import dataclass

import numpy as np

from feederkit.errors import InputError
from feederkit.hull import diameter_of
from feederkit.mechanics.analysis import fragile_member_warnings, tipping_warnings
from feederkit.mechanics.push import PushFunction, StableState, push_function
from feederkit.outline import make_outline
from feederkit.part import make_part
from feederkit.planning.tree import Certificate
from feederkit.sensors import Sensor
from feederkit.uncertainty import IDEAL, Uncertainty

Point = tuple[float, float]


@dataclass(frozen=True)
class PlanPart:
    """A member of the plan's mix as the plan records it: hull and COM (part frame), states.

    ``states`` are the stable states the plan lists (the diameters it was planned on); the
    push function the hull and COM give is :func:`push_function_of`. A plan over landings
    (design.md, "Landings") has one member per landing of each part: ``landing`` is
    ``"up"``, ``"down"`` or ``"pose-K"`` (the hull and COM are the part as it then lies) and
    ``share`` the member's prior probability (part share times landing probability; None:
    every member equally likely). A member is identified by ``(name, landing)``.
    """

    name: str
    revision: str | int | None
    com: Point
    hull: tuple[Point, ...]
    states: tuple[StableState, ...]
    landing: str | None = None
    share: float | None = None

    @property
    def key(self) -> tuple[str, str | None]:
        """``(name, landing)``: what result entries name."""
        return (self.name, self.landing)

    @property
    def label(self) -> str:
        """The member in words: ``NAME`` or ``NAME (LANDING)``."""
        return member_label(self.name, self.landing)

    def state(self, sid: int) -> StableState:
        """The listed state with id ``sid``; an unknown id is bad input."""
        for s in self.states:
            if s.id == sid:
                return s
        raise InputError(f"plan: part {self.name!r} lists no stable state {sid}")

    @functools.cached_property
    def size(self) -> float:
        """The hull's diameter (mm), as :attr:`feederkit.part.Part.size`: the scale of
        geometric tolerances, the same however the drawing turns the part."""
        return diameter_of(self.hull)


@functools.lru_cache(maxsize=256)
def push_function_of(part: PlanPart) -> PushFunction:
    """The push function of a plan's part, rebuilt from its hull and COM only (section 3.1).

    Cached by the (frozen, hashable) part: execution, verification, reports and the simulator
    of one plan share one rebuild.
    """
    outline = make_outline(part.name, [list(p) for p in part.hull], com=list(part.com))
    revision = None if part.revision is None else str(part.revision)
    # The file's hull is the contact polygon as planned: re-hull it exactly (tolerance 0),
    # never simplify it again, so it is numbered and shaped as it was written.
    return push_function(make_part(outline, hull_tolerance=0.0, revision=revision))


def member_label(name: str, landing: str | None) -> str:
    """A member of a plan in words: ``NAME``, or ``NAME (LANDING)`` in a plan over landings."""
    return name if landing is None else f"{name} ({landing})"


def member_name(part: str, landing: str | None) -> str:
    """A plan member as its push function is named: ``PART``, or ``PART/LANDING`` in a plan
    over landings (:attr:`feederkit.landing.model.Landing.label`): how the mix analysis and
    its pairs name it (docs/landings.md)."""
    return part if landing is None else f"{part}/{landing}"


Member = tuple[str, str | None]
"""A plan member as ``(part, landing)`` (landing None: a plan not over landings)."""


def side_words(landings: Iterable[str | None], part: str | None = None) -> str:
    """What the plan does not know of a part whose ``landings`` a result lists together:
    ``which side is up`` (a flat part's ``up`` and ``down``) or ``which pose it lies in`` (a
    mesh's poses); ``part`` named in it when given."""
    if set(landings) <= {"up", "down"}:
        return "which side is up" if part is None else f"which side of {part} is up"
    return "which pose it lies in" if part is None else f"which pose {part} lies in"


def pairs_words(subject: str, pairs: Sequence[tuple[Member, Member, str]]) -> str:
    """One line naming the pairs of members no plan tells apart (section 8.4), each
    ``(member_a, member_b, reason)``, for ``plan`` and ``changeover compile`` alike.

    Pairs of two parts: ``SUBJECT cannot tell these apart: A & B (reason); ...``. Two landings
    of one part: the plan knows the part (unless one of its landings pairs with another
    part) but neither its side nor its pose, so the part is not oriented and the words never
    say it is: ``SUBJECT recognizes X but not which side is up: X/up & X/down (reason): X is
    not oriented``. Members are named :func:`member_name`-wise, as the mix analysis names
    them.
    """

    def named(group: Sequence[tuple[Member, Member, str]]) -> str:
        return "; ".join(f"{member_name(*a)} & {member_name(*b)} ({why})" for a, b, why in group)

    across = [p for p in pairs if p[0][0] != p[1][0]]
    clauses = [f"cannot tell these apart: {named(across)}"] if across else []
    mixed_up = {m[0] for a, b, _ in across for m in (a, b)}
    sides: dict[str, list[tuple[Member, Member, str]]] = {}
    for pair in pairs:
        if pair[0][0] == pair[1][0]:
            sides.setdefault(pair[0][0], []).append(pair)
    for part, group in sides.items():
        landings = [m[1] for a, b, _ in group for m in (a, b)]
        if part in mixed_up:
            lead = f"cannot tell {side_words(landings, part)}"
        else:
            lead = f"recognizes {part} but not {side_words(landings)}"
        clauses.append(f"{lead}: {named(group)}: {part} is not oriented")
    listed = "; its results list each candidate with its pose"
    return f"{subject} " + "; and it ".join(clauses) + listed


def member_fragile_warnings(
    members: Iterable[tuple[str, str | None, PushFunction]],
) -> list[str]:
    """The fragile states of a plan's members ``(name, landing, push function)`` in words
    (:func:`~feederkit.mechanics.analysis.fragile_member_warnings`), each member named by
    :func:`member_label`: ``l-bracket: fragile states 1`` in a plan not over landings, and
    in a plan over landings each landing with its own state numbers, one line per part
    (``l-bracket (up): fragile states 1; l-bracket (down): fragile states 3``). Every
    landing says its own: a flat part's down side is the mirror image of its up side, as
    fragile, but numbers its states differently, and a mesh's poses are different shapes.
    """
    parts: dict[str, list[tuple[str, PushFunction]]] = {}
    for name, landing, pf in members:
        parts.setdefault(name, []).append((member_label(name, landing), pf))
    tipping = [line for ms in parts.values() for line in tipping_warnings(ms)]
    return fragile_member_warnings(list(parts.values())) + tipping


def names_several(members: Iterable[tuple[str, str | None]], reject: bool = False) -> bool:
    """Whether an accept result naming ``members`` (``(part, landing)``, repeats allowed)
    leaves the part unrecognized: it names more than one part or landing, which the plan
    cannot tell apart (each entry is still a correct answer, design.md). A reject result
    never does: every member it names is recirculated alike."""
    return not reject and len(set(members)) > 1


UNRECOGNIZED_WORDS = (
    "unrecognized (a result listing several parts or landings the plan cannot tell apart: "
    "the part is one of them, each with its pose, but not known which)"
)
"""How ``run --all``, ``simulate`` and the report name the successes that ended in an accept
result naming several members (:func:`names_several`)."""


@dataclass(frozen=True)
class ResultEntry:
    """One correct answer of a leaf: part ``part``, lying in ``landing`` (None: a plan not
    made over landings), resting in its state ``state``."""

    part: str
    state: int
    pose_deg: float
    landing: str | None = None

    @property
    def key(self) -> tuple[str, str | None]:
        """``(part, landing)``: the plan member the entry names."""
        return (self.part, self.landing)


@dataclass(frozen=True)
class Leaf:
    """The end of a plan: the part rests in one of ``results`` (several: no plan tells them
    apart).

    ``reject``: the landings listed are ones the next station cannot take (design.md,
    "Landings"); the controller recirculates or re-drops the part (docs/plans.md).
    """

    results: tuple[ResultEntry, ...]
    reject: bool = False

    @property
    def candidates(self) -> tuple[tuple[str, str | None], ...]:
        """The members ``(part, landing)`` the result names, each once, in result order."""
        return tuple(dict.fromkeys(r.key for r in self.results))

    @property
    def unrecognized(self) -> bool:
        """Whether this is an accept result naming several members (:func:`names_several`):
        the part is one of them, and the controller cannot know which."""
        return names_several(self.candidates, self.reject)

    def accepts(self, part: str, state: int, landing: str | None = None) -> bool:
        """Whether ``part`` lying in ``landing`` and resting in ``state`` is one of the
        answers (for a reject leaf: one of the states it rejects)."""
        return any(
            r.part == part and r.state == state and r.landing == landing for r in self.results
        )


@dataclass(frozen=True)
class PlanMember:
    """What a plan maker knows of one member beyond its push function: its name and landing
    in the plan file, its prior share, and whether the next station takes it (``accept``
    False: sets of its states end in reject leaves)."""

    name: str
    landing: str | None = None
    share: float | None = None
    accept: bool = True


@dataclass(frozen=True)
class Branch:
    """Follow ``next`` when the reading lies in the closed interval ``reading``.

    ``reading`` is None only in a sensorless plan, whose single branch holds every reading.
    """

    reading: tuple[float, float] | None
    next: Node

    def holds(self, reading: float | None) -> bool:
        """Whether this branch may be followed on ``reading`` (design.md: closed ``[lo, hi]``).

        This is the one rule every consumer follows: no slack, so a reading on a shared
        endpoint is held by both branches (each must be right for it).
        """
        if self.reading is None:
            return True
        return reading is not None and self.reading[0] <= reading <= self.reading[1]


@dataclass(frozen=True)
class Step:
    """One push-align operation: rotate by ``action_deg`` (None at the root), align, read.

    ``margin_deg`` is the half-width of the action's overlap range (section 6): every
    rotation in ``action_deg ± margin_deg`` must lead every state to the same outcome.
    """

    action_deg: float | None
    margin_deg: float | None
    branches: tuple[Branch, ...]

    def __post_init__(self) -> None:
        # A plan may share subtrees (a DAG with astronomically many paths): the structural
        # hash is computed once, from the children's, so hashing never walks the paths.
        key = (self.action_deg, self.margin_deg, tuple(self.branches))
        object.__setattr__(self, "_hash", hash(key))

    def __hash__(self) -> int:
        return self._hash  # type: ignore[attr-defined,no-any-return]

    def __repr__(self) -> str:
        # one level only: the repr of a shared subtree would repeat it once per path
        readings = ", ".join(str(b.reading) for b in self.branches)
        return f"Step(action_deg={self.action_deg!r}, margin_deg={self.margin_deg!r}, " + (
            f"branches on readings [{readings}])"
        )

    @property
    def overlap_range(self) -> tuple[float, float] | None:
        """The rotations ``(action - margin, action + margin)`` (None at the root)."""
        if self.action_deg is None or self.margin_deg is None:
            return None
        return self.action_deg - self.margin_deg, self.action_deg + self.margin_deg

    def held_by(self, reading: float | None) -> tuple[int, ...]:
        """The indices of the branches that hold ``reading`` (:meth:`Branch.holds`), in order.

        A step with many branches compares the reading with arrays of their ends (the
        same closed comparisons, made once per step and reading instead of per branch).
        """
        if reading is None:
            return tuple(k for k, b in enumerate(self.branches) if b.holds(reading))
        return self.meeting(reading, reading)  # Branch.holds's closed test, one point

    def meeting(self, lo: float, hi: float) -> tuple[int, ...]:
        """The indices of the branches whose reading interval meets the closed ``[lo, hi]``
        (a branch without one meets every interval), in order: the only ones a state whose
        readings lie in ``[lo, hi]`` can follow (``Sensor.branch_reach``)."""
        if len(self.branches) < _INDEXED_BRANCHES:
            return tuple(
                k
                for k, b in enumerate(self.branches)
                if b.reading is None or (b.reading[0] <= hi and lo <= b.reading[1])
            )
        ends_lo, ends_hi, ascending = self._ends()
        if ascending is not None:
            # Both ends ascending (the planner's reading cells): the branches meeting
            # [lo, hi] are one run, from the first reaching lo to the last starting by hi.
            los, his = ascending
            return tuple(range(bisect.bisect_left(his, lo), bisect.bisect_right(los, hi)))
        return tuple(((ends_lo <= hi) & (lo <= ends_hi)).nonzero()[0].tolist())

    def _ends(self) -> tuple[np.ndarray, np.ndarray, tuple[list[float], list[float]] | None]:
        """The branches' reading intervals' ends as two arrays, and as two lists when both
        ascend (None otherwise: a hand-written file), made once per step."""
        table = self.__dict__.get("_ends_table")
        if table is None:
            inf = math.inf
            los = [-inf if b.reading is None else float(b.reading[0]) for b in self.branches]
            his = [inf if b.reading is None else float(b.reading[1]) for b in self.branches]
            ascending = all(
                a0 <= a1 and b0 <= b1
                for a0, a1, b0, b1 in zip(los, los[1:], his, his[1:], strict=False)
            )
            table = (np.array(los), np.array(his), (los, his) if ascending else None)
            object.__setattr__(self, "_ends_table", table)
        return table

    def follow(self, reading: float | None) -> int | None:
        """The first branch that holds ``reading``; None: a foreign part or a sensor fault."""
        held = self.held_by(reading)
        return held[0] if held else None


_INDEXED_BRANCHES = 8
"""Steps with at least this many branches find the ones holding a reading by arrays."""

Node = Step | Leaf


@dataclass(frozen=True)
class PlanStats:
    """The plan file's ``stats`` (design.md and feederkit's own fields, see plans/stats.py).

    ``min_margin_deg`` is None when the plan makes no rotation; the Fig. 14 class fields are
    None for a mix.
    """

    length: int
    expected_length: float
    min_margin_deg: float | None
    optimal: bool
    lower_bound: int
    objective: str | None = None
    grouping: str | None = None
    polygon_class: int | None = None
    class_bound: int | None = None
    meets_bound: bool | None = None
    certificate: Certificate | None = None


def operations_below(root: Node) -> int:
    """The most operations on any path from ``root`` to a leaf (0 at a leaf), memoised per
    distinct node, without recursion."""
    memo: dict[int, int] = {}
    stack: list[tuple[Node, bool]] = [(root, False)]
    while stack:
        node, expanded = stack.pop()
        if id(node) in memo:
            continue
        if isinstance(node, Leaf):
            memo[id(node)] = 0
        elif expanded:
            memo[id(node)] = 1 + max(memo[id(b.next)] for b in node.branches)
        else:
            stack.append((node, True))
            stack.extend((b.next, False) for b in node.branches if id(b.next) not in memo)
    return memo[id(root)]


REJECTED_WORDS = "rightly rejected (a reject leaf naming the landing)"
"""How the simulator's outputs (the command line, the report) name the successes that ended
in a reject leaf naming the member's landing (design.md, "Landings")."""

LOW_MARGIN_DEG = 1.0
"""Below this smallest margin no robot holds the plan's rotations: every output warns."""


def robust_ideal_words(length: int, ideal_length: int | None) -> str:
    """The certificate's "length: robust / ideal model" figure, with why a robust plan can be
    the shorter: a strong plan under uncertainty is a plan on the ideal model too (for the
    same goal), so a shorter one lists together in its results poses the ideal model's plan
    tells apart (lumping; docs/uncertainty.md).

    >>> robust_ideal_words(2, 3)
    '2 / 3 (shorter: its results list together poses the ideal model tells apart)'
    """
    if ideal_length is None:
        return f"{length} / not computed"
    why = (
        " (shorter: its results list together poses the ideal model tells apart)"
        if ideal_length > length
        else ""
    )
    return f"{length} / {ideal_length}{why}"


def low_margin_words(min_margin_deg: float | None, rotation_error_deg: float = 0.0) -> str | None:
    """One line when a plan holds rotations off by less than :data:`LOW_MARGIN_DEG`: its
    declared rotation error plus its smallest margin (None: no rotation, or enough).

    >>> low_margin_words(0.5) is None, low_margin_words(0.5, 1.0) is None
    (False, True)
    """
    m = min_margin_deg
    if m is None or not math.isfinite(m):
        return None
    held = m + rotation_error_deg
    if held >= LOW_MARGIN_DEG:
        return None
    if rotation_error_deg > 0.0:
        return (
            f"the plan holds rotation errors up to ±{held:.3g}° (declared ±{rotation_error_deg:g}° "
            f"plus its smallest margin ±{m:.3g}°), below ±{LOW_MARGIN_DEG:g}°: a robot whose "
            "rotations err by more will not follow the plan"
        )
    return (
        f"the plan's smallest margin is ±{m:.2g}°, below ±{LOW_MARGIN_DEG:g}°: no robot holds "
        f"±{m:.2g}°, and a robot whose rotations err by more will not follow the plan"
    )


def ideal_plan_words(
    unc: Uncertainty, min_margin: float, certificate: Certificate | None
) -> str | None:
    """One line when a plan made on the ideal model holds less on a feeder that vibrates
    than its margins say: the certificate is computed with the vibration the planner's
    model has under any rotation error (fragile states merged, a push band at each hilltop,
    ``strong.strong_model``), where an ideal plan may hold no rotation error at all.

    >>> print(ideal_plan_words(IDEAL, 5.0, Certificate(3.0, 0.0, 2)))
    the plan is the ideal model's: on a feeder that vibrates it holds rotation errors up to ±3° ...
    """
    if not unc.is_ideal or certificate is None or not math.isfinite(min_margin):
        return None
    held = certificate.max_rotation_error_deg
    if held >= min_margin - 1e-9:
        return None
    what = "no rotation error at all" if held <= 0.0 else f"rotation errors up to ±{held:.4g}°"
    return (
        f"the plan is the ideal model's: on a feeder that vibrates it holds {what} (its "
        f"margins say ±{min_margin:.4g}°: drops near a hilltop may go either way, fragile "
        "states merge); plan with --rotation-error DEG for one that holds it"
    )


@dataclass(frozen=True)
class Plan:
    """A plan: its sensor, its declared uncertainty, its parts (in order), the tree from
    ``root``, and ``stats``.

    ``uncertainty`` is what the plan is strong for (design.md, "Uncertainty");
    ``uncertainty_declared`` is False for a version-1 file that declares none, read as the
    paper's ideal model (every output that shows the uncertainty says so).
    """

    sensor: Sensor
    parts: tuple[PlanPart, ...]
    root: Step
    stats: PlanStats
    conventions: str
    uncertainty: Uncertainty = IDEAL
    uncertainty_declared: bool = True

    def uncertainty_words(self) -> str:
        """The declared uncertainty in one line (saying when a file declared none)."""
        u = self.uncertainty
        text = (
            f"rotation error ±{u.rotation_error_deg:g}°, shape tolerance "
            f"{u.shape_tolerance_mm:g} mm, COM tolerance {u.com_tolerance_mm:g} mm"
        )
        if not self.uncertainty_declared:
            return f"none declared (a version-1 plan): the ideal model, {text}"
        return f"{text} (the ideal model)" if u.is_ideal else text

    def certificate_words(self) -> str | None:
        """The certificate in one line (None when the plan carries none)."""
        c = self.stats.certificate
        if c is None:
            return None
        return (
            f"holds up to rotation error ±{c.max_rotation_error_deg:.4g}° and shape tolerance "
            f"{c.max_shape_tolerance_mm:.4g} mm; length robust / ideal model "
            f"{robust_ideal_words(self.stats.length, c.ideal_length)}"
        )

    def part(self, name: str, landing: str | None = None) -> PlanPart:
        """The member ``(name, landing)``; an unknown one is bad input (see
        :meth:`part_index`)."""
        return self.parts[self.part_index(name, landing)]

    def part_index(self, name: str, landing: str | None = None) -> int:
        """The index of the member ``(name, landing)``.

        Without a landing, a name that only one member has is enough; an unknown member,
        or a name several landings share, is bad input.
        """
        for k, p in enumerate(self.parts):
            if p.name == name and p.landing == landing:
                return k
        named = [k for k, p in enumerate(self.parts) if p.name == name]
        if landing is None and len(named) == 1:
            return named[0]
        if not named:
            raise InputError(f"plan: no part named {name!r}")
        if landing is None:
            which = ", ".join(str(self.parts[k].landing) for k in named)
            raise InputError(f"plan: part {name!r} has several landings ({which}): name one")
        raise InputError(f"plan: part {name!r} has no landing {landing!r}")

    def shares(self) -> tuple[float, ...]:
        """Each member's prior probability, normalised to sum 1 (equal when none is given):
        the weights of the expected length."""
        given = [p.share for p in self.parts]
        if any(x is None for x in given):
            return tuple(1.0 / len(self.parts) for _ in self.parts)
        total = math.fsum(x for x in given if x is not None)
        return tuple((x or 0.0) / total for x in given)

    @property
    def over_landings(self) -> bool:
        """Whether the plan was made over landings (its members name them)."""
        return any(p.landing is not None for p in self.parts)

    def push_functions(self) -> tuple[PushFunction, ...]:
        """Each part's push function, rebuilt from its hull and COM (cached)."""
        return tuple(push_function_of(p) for p in self.parts)

    def walk(self) -> Iterator[tuple[Node, int]]:
        """Every distinct node of the plan once (a shared subtree at its first place), with
        the operation number of that place (the root 1, a leaf the number of the step above
        it), pre-order, without recursion. For a plan without shared nodes this is every
        node of the tree."""
        seen: set[int] = set()
        stack: list[tuple[Node, int]] = [(self.root, 1)]
        while stack:
            node, number = stack.pop()
            if id(node) in seen:
                continue
            seen.add(id(node))
            yield node, number
            if isinstance(node, Step):
                for b in reversed(node.branches):
                    if id(b.next) not in seen:
                        nxt = number + 1 if isinstance(b.next, Step) else number
                        stack.append((b.next, nxt))

    def leaves(self) -> list[Leaf]:
        """The distinct result nodes in pre-order (a shared leaf once)."""
        return [n for n, _ in self.walk() if isinstance(n, Leaf)]

    def depth(self) -> int:
        """The most operations on any root-to-leaf path, memoised per distinct node (linear
        in the distinct nodes however many paths share them)."""
        return operations_below(self.root)

    def smallest_margin(self) -> float | None:
        """The smallest ``margin_deg`` of any rotation in the tree (None: no rotation)."""
        margins = [
            n.margin_deg for n, _ in self.walk() if isinstance(n, Step) and n.margin_deg is not None
        ]
        return min(margins) if margins else None

    def fragile_warnings(self, members: Sequence[int] | None = None) -> list[str]:
        """The fragile states of the plan's members in words, as ``plan`` warned when it
        made the plan (:func:`member_fragile_warnings`, from the hulls and COMs the plan
        records): in a plan over landings, every landing named as the results name it, with
        its own state numbers. ``members``: only those (indices into ``parts``)."""
        chosen = range(len(self.parts)) if members is None else members
        return member_fragile_warnings(
            (p.name, p.landing, push_function_of(p)) for p in (self.parts[k] for k in chosen)
        )

    def low_margin_warning(self) -> str | None:
        """A warning when the plan holds rotation errors below LOW_MARGIN_DEG (None otherwise).

        A strong plan's margins are slack beyond its declared rotation error (its outcome
        sets already cover that error), so what it holds is the two together."""
        return low_margin_words(self.stats.min_margin_deg, self.uncertainty.rotation_error_deg)

    def ideal_model_warning(self) -> str | None:
        """A warning when the plan was made on the ideal model and its certificate holds less
        on a feeder that vibrates than its margins say (None otherwise): ``plan`` says it when
        it makes the plan, and ``run``, ``simulate`` and the report say it again of the file."""
        margin = self.stats.min_margin_deg
        if margin is None:
            return None
        return ideal_plan_words(self.uncertainty, margin, self.stats.certificate)
