"""The hybrid automaton of a scene: its modes, switching surfaces, transitions and resets.

The model switches between vector fields (Eq. 10 in contact, Eq. 15 in free flight, each
damping law of models D and E, each direction of Coulomb friction).  This module states,
as data, which modes a scene has and how it goes from one to another; ``derive.scenes``
derives the field of each mode and the value of each surface, and ``derive.codegen`` writes
both into the scene's module, where the runtime engine reads them.  Nothing here needs SymPy.

Semantics (the engine implements exactly these rules, once):

* A **mode** watches the surfaces of its transitions.  A transition fires when its surface's
  value crosses zero in its direction during a step: +1 from < 0 to >= 0, -1 from > 0 to <= 0.
  The earliest crossing in time wins; ties go to the transition listed first.
* The **target** of a transition is the first of its candidates whose conditions hold at the
  switching state.  A condition (surface, sign) holds where sign * value >= 0, the value taken
  under the candidate's own laws; exactly on a surface (value 0), the value a moment later
  along the motion decides (alpha moved by alpha_dot over 1e-9 s).  The last candidate has no
  condition, so a target always exists.
* The state after the switch is the transition's **reset** of the state before it: the
  identity where the contact is compliant; the rigid law's impact is a reset (Newton's law), and a
  chatter of impacts converging geometrically ends with the automaton's ``chatter`` transition in its
  place (the engine's rule, camdyn.engine.rules.chatter_ends).
* The **initial** mode is chosen by the same rule from the ``initial`` candidates.

Modes and their surfaces (non-linear model):

  free --(gap, -1)--> contact (entering: the damping law and the friction direction read off
                               the state: impact law if psi_i_dot <= 0, forward if v_r >= 0)
  contact --(gap, +1)--> free
  contact_loading_* --(gap_rate, +1)--> contact_unloading_*    models D, E: maximum compression
  contact_unloading_* --(gap_rate, -1)--> contact_loading_*    only with damping_switch="memoryless"
  contact_*_fwd --(slip, -1)--> contact_*_stick if both one-sided fields point at v_r = 0
                                (Filippov sliding mode, misprint 12), else contact_*_bwd
  contact_*_stick --(slip_rate_fwd, +1)--> contact_*_fwd; --(slip_rate_bwd, -1)--> contact_*_bwd
  contact_* --(junction, +1 or -1)--> the same mode   a cam of arcs: the step restarts where the
                                                       contact passes from one arc to the next
  contact_* --(face, -1)--> off_face                   a bounded face: the contact reached an end of
                                                       it; off_face is terminal (the run ends there,
                                                       Outcome.OFF_FACE), and so is an impact that
                                                       would land beyond an end

With ``damping_switch="episode"`` (the default, Sec. 3.4) the impact law acts from first
contact to maximum compression and the viscous law from there to separation: the law is
latched for the rest of the contact episode, and reset by the next impact.
"""
from __future__ import annotations

from dataclasses import dataclass

from camdyn.vocabulary import SceneSpec, mode_name


@dataclass(frozen=True)
class Mode:
    """A discrete state: in contact or not, which damping law, which friction direction."""

    name: str
    contact: bool
    phase: str | None = None   # models D, E (non-linear): "impact" or "viscous"
    slip: str | None = None    # Coulomb friction: "fwd", "bwd" or "stick"
    terminal: bool = False     # the run ends on entering it (its fields are free flight's, never integrated)


@dataclass(frozen=True)
class Condition:
    """Holds where sign * value(surface) >= 0 (see the module docstring)."""

    surface: str
    sign: int


@dataclass(frozen=True)
class Target:
    """A candidate mode of a transition and the conditions under which it is entered."""

    mode: str
    conditions: tuple[Condition, ...] = ()


@dataclass(frozen=True)
class Transition:
    """Leave ``source`` when ``surface`` crosses zero in ``direction``, for the first target
    whose conditions hold, through ``reset``."""

    source: str
    surface: str
    direction: int
    targets: tuple[Target, ...]
    reset: str = "identity"


@dataclass(frozen=True)
class Automaton:
    modes: tuple[Mode, ...]
    surfaces: tuple[str, ...]
    #: surface -> the surface that is its time derivative: an excursion of the first across
    #: zero and back inside one step is found where the second changes sign
    rates: dict[str, str]
    initial: tuple[Target, ...]
    transitions: tuple[Transition, ...]
    resets: tuple[str, ...] = ("identity",)
    #: the rigid law's chatter end: a transition of the same source, surface and direction as the impact
    #: it replaces where the engine finds the impacts converging geometrically (camdyn.engine.rules.chatter_ends)
    chatter: Transition | None = None
    #: the surfaces whose value is a function of time alone (derived: free of the state, e.g. a cam of arcs'
    #: junctions under a translating follower, of Theta(t) only): the engine steps to their crossings
    #: (camdyn.engine.rules.time_bound) instead of searching a step for them, as a field that jumps there
    #: could not be stepped across
    timed: tuple[str, ...] = ()

    def mode(self, name: str) -> Mode:
        return next(m for m in self.modes if m.name == name)

    def watched(self, mode: str) -> tuple[Transition, ...]:
        return tuple(tr for tr in self.transitions if tr.source == mode)


def _phases(spec: SceneSpec) -> tuple[str | None, ...]:
    return ("impact", "viscous") if spec.switched_damping else (None,)


def _slips(spec: SceneSpec, stick: bool) -> tuple[str | None, ...]:
    """Coulomb friction's discrete states: the sliding directions, and stuck (the non-linear model).
    None for a translating follower: its face's friction acts across the ideal guide and does no
    work on its coordinate (derive.translating), so its direction changes no field, only the
    outputs, which take the sign of v_r itself."""
    if spec.friction != "coulomb" or spec.follower == "translating":
        return (None,)
    return ("fwd", "bwd", "stick") if stick and spec.model == "nonlinear" else ("fwd", "bwd")


#: the terminal mode of a bounded face: the contact is beyond an end of the follower's face
OFF_FACE = "off_face"


def modes(spec: SceneSpec) -> tuple[Mode, ...]:
    out = [Mode("free", False)] if spec.model == "nonlinear" else []
    for phase in _phases(spec):
        for slip in _slips(spec, stick=True):
            out.append(Mode(mode_name(True, phase, slip), True, phase, slip))
    if spec.face == "bounded":
        out.append(Mode(OFF_FACE, False, terminal=True))
    return tuple(out)


def _on_face(targets: tuple[Target, ...], last: Target) -> tuple[Target, ...]:
    """A bounded face: each contact candidate only where the contact lands on the face (face >= 0),
    then ``last`` (the terminal off_face, or for the initial rule the candidates that follow)."""
    return tuple(Target(t.mode, t.conditions + (Condition("face", +1),)) for t in targets) + (last,)


def _entering(spec: SceneSpec, extra: tuple[Condition, ...] = ()) -> tuple[Target, ...]:
    """Contact starts in the impact law where the gap closes (psi_i_dot <= 0) and slides forward
    where v_r >= 0: the candidates in that order, the last without a condition."""
    out = []
    for phase in _phases(spec):
        for slip in _slips(spec, stick=False):
            conditions = list(extra)
            if phase == "impact":
                conditions.append(Condition("gap_rate", -1))
            if slip == "fwd":
                conditions.append(Condition("slip", +1))
            out.append(Target(mode_name(True, phase, slip), tuple(conditions)))
    return tuple(out)


def _slip_transitions(spec: SceneSpec, mode: Mode) -> list[Transition]:
    """Coulomb friction: a reversal of v_r sticks if both one-sided fields point at v_r = 0;
    a stuck follower slips when one of them turns away."""
    same = {s: mode_name(True, mode.phase, s) for s in ("fwd", "bwd", "stick")}
    if mode.slip == "stick":
        return [Transition(mode.name, "slip_rate_fwd", +1, (Target(same["fwd"]),)),
                Transition(mode.name, "slip_rate_bwd", -1, (Target(same["bwd"]),))]
    attracted = (Condition("slip_rate_fwd", -1), Condition("slip_rate_bwd", +1))
    other = "bwd" if mode.slip == "fwd" else "fwd"
    direction = -1 if mode.slip == "fwd" else +1
    return [Transition(mode.name, "slip", direction, (Target(same["stick"], attracted), Target(same[other])))]


def _damping_transitions(spec: SceneSpec, mode: Mode) -> list[Transition]:
    """Models D, E: the impact law ends at maximum compression (psi_i_dot turns positive); the
    memoryless reading also goes back to it where psi_i_dot turns negative again."""
    if mode.phase == "impact":
        return [Transition(mode.name, "gap_rate", +1, (Target(mode_name(True, "viscous", mode.slip)),))]
    if mode.phase == "viscous" and spec.damping_switch == "memoryless":
        return [Transition(mode.name, "gap_rate", -1, (Target(mode_name(True, "impact", mode.slip)),))]
    return []


#: the rigid law's resets: Newton's impact law, and the plastic impact that ends a chatter
IMPACT, PLASTIC = "impact", "plastic"


def _rigid(spec: SceneSpec) -> Automaton:
    """The rigid contact law (derive.rigid): free flight bounces off the cam at the gap with Newton's
    impact law (a reset; the follower flies on), and a chatter of impacts converging geometrically ends
    in the constrained mode ``contact`` (the plastic reset) where its contact force is compressive; the
    follower leaves the constrained mode where the contact force turns negative (with the plastic reset:
    it leaves with no relative velocity)."""
    free, contact = Mode("free", False), Mode(mode_name(True), True)
    # leaving the cam, the follower rode it: its relative velocity is 0, the plastic reset makes it so exactly
    # (the constrained mode's numerical drift, ~1e-9 m/s, would otherwise start a flight approaching the cam)
    transitions = (Transition("free", "gap", -1, (Target("free"),), IMPACT),
                   Transition(contact.name, "contact_force", -1, (Target("free"),), PLASTIC))
    riding = Target(contact.name, (Condition("contact_force", +1),))
    chatter = Transition("free", "gap", -1, (riding, Target("free")), PLASTIC)
    initial = (Target(contact.name, (Condition("gap", -1), Condition("contact_force", +1))), Target("free"))
    surfaces = ("gap", "gap_rate", "contact_force")
    if spec.profile == "arcs":  # the constrained acceleration jumps with the curvature: restart there, and
        # leave where the contact force it needs jumps below zero (a corner of the cam flings the follower)
        surfaces += ("junction",)
        transitions += tuple(Transition(contact.name, "junction", d, (riding, Target("free")), PLASTIC) for d in (+1, -1))
    return Automaton((free, contact), surfaces, {"gap": "gap_rate"}, initial, transitions,
                     ("identity", IMPACT, PLASTIC), chatter)


def build(spec: SceneSpec) -> Automaton:
    """The automaton of a scene (see the module docstring)."""
    if spec.contact == "rigid":
        return _rigid(spec)
    all_modes = modes(spec)
    coulomb = spec.friction == "coulomb"
    if spec.model != "nonlinear":  # sliding contact throughout; the friction sign fixed at the start
        surfaces = ("slip",) if coulomb else ()
        return Automaton(all_modes, surfaces, {}, _entering(spec), ())
    coulomb = coulomb and spec.follower != "translating"  # (see _slips)
    surfaces = ("gap", "gap_rate") + (("slip", "slip_rate_fwd", "slip_rate_bwd") if coulomb else ())
    transitions = [Transition("free", "gap", -1, _entering(spec))]
    for mode in (m for m in all_modes if m.contact):
        transitions.append(Transition(mode.name, "gap", +1, (Target("free"),)))
        transitions += _damping_transitions(spec, mode)
        if coulomb:
            transitions += _slip_transitions(spec, mode)
    if spec.profile == "arcs":  # the curvature jumps at a junction of arcs: restart there, same mode
        surfaces += ("junction",)
        transitions += [Transition(mode.name, "junction", direction, (Target(mode.name),))
                        for mode in all_modes if mode.contact for direction in (+1, -1)]
    initial = _entering(spec, (Condition("gap", -1),)) + (Target("free"),)
    if spec.face == "bounded":
        surfaces += ("face",)
        transitions = [Transition(tr.source, tr.surface, tr.direction, _on_face(tr.targets, Target(OFF_FACE)))
                       if tr.source == "free" else tr for tr in transitions]
        transitions += [Transition(mode.name, "face", -1, (Target(OFF_FACE),)) for mode in all_modes if mode.contact]
        initial = _on_face(initial[:-1], Target(OFF_FACE, (Condition("gap", -1),))) + initial[-1:]
    return Automaton(all_modes, surfaces, {"gap": "gap_rate"}, initial, tuple(transitions))
