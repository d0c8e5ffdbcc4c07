"""The hybrid automaton's names and the layouts of the generated kernels' results: modes,
surfaces, outputs, the state, the Jacobian's and the surface gradient's entries (shared by
derive/ and the runtime; plain Python, no SymPy)."""
from __future__ import annotations

# --- the hybrid automaton: mode and surface names -------------------------------------------
#: the damping law a contact mode uses (models D, E: "impact" from t_a to t_b, then "viscous")
DAMPING_PHASES = ("impact", "viscous")
#: Coulomb friction: the direction of sliding (v_r > 0 forward), or stuck on v_r = 0
SLIP_STATES = ("fwd", "bwd", "stick")


def mode_name(contact: bool, phase: str | None = None, slip: str | None = None) -> str:
    """The name of a mode: ``free``, or ``contact`` with ``_loading``/``_unloading`` (models D, E:
    the impact and the viscous law) and ``_fwd``/``_bwd``/``_stick`` (Coulomb friction)."""
    if not contact:
        return "free"
    name = "contact"
    if phase is not None:
        name += {"impact": "_loading", "viscous": "_unloading"}[phase]
    if slip is not None:
        name += "_" + slip
    return name


#: the columns of a scene module's TRANSITIONS rows, in order (derive writes them, the engine
#: reads them by these indices): the source mode, the surface crossed, the direction (+1 upward,
#: -1 downward), the candidate targets ((mode, conditions), ...), the reset
TRANSITION = ("source", "surface", "direction", "targets", "reset")
TRANSITION_SOURCE, TRANSITION_SURFACE, TRANSITION_DIRECTION, TRANSITION_TARGETS, TRANSITION_RESET = \
    range(len(TRANSITION))

#: Switching surfaces: name -> (unit, meaning).  A surface's value is a function of the state
#: (t, alpha, alpha_dot) under a mode's laws; its sign selects modes (see derive.automaton).
SURFACES: dict[str, tuple[str, str]] = {
    "gap": ("m", "gap psi_i (Eq. 6): the follower touches the cam where it is negative"),
    "gap_rate": ("m/s", "gap rate psi_i_dot (Eq. 8): zero at maximum compression (t_b of Eqs. 27-28)"),
    "slip": ("m/s", "sliding velocity v_r: the direction of Coulomb friction"),
    "slip_rate_fwd": ("m/s^2", "dv_r/dt under the forward-sliding field: the stuck follower slips "
                               "forward where it turns positive"),
    "slip_rate_bwd": ("m/s^2", "dv_r/dt under the backward-sliding field: the stuck follower slips "
                               "backward where it turns negative"),
    "junction": ("1", "a cam of circular arcs (profile 'arcs'): zero where the contact passes a junction of "
                      "two arcs, where the curvature jumps; the step restarts there, in the same mode"),
    "contact_force": ("N", "the rigid contact's normal force in the constrained mode (contact 'rigid'): the "
                           "follower leaves the cam where it turns negative"),
    "face": ("m^2", "a bounded face (face 'bounded'): (s - face_start)(face_end - s) of the contact's position s "
                    "along the face, negative where the contact is beyond an end"),
}

# --- output quantities ------------------------------------------------------------------------
#: Output quantities of every scene, in the order of the generated ``outputs`` kernel:
#: name -> (unit, meaning with the paper's equation).
OUTPUTS: dict[str, tuple[str, str]] = {
    "psi_i": ("m", "gap; negative: contact deflection (Eq. 6)"),
    "psi_j": ("m", "sliding of the contact point along the follower (Eq. 7)"),
    "psi_i_dot": ("m/s", "gap rate (Eq. 8)"),
    "F_s": ("N", "spring force (Eq. 11)"),
    "F_n": ("N", "normal contact force (Eq. 12)"),
    "F_f": ("N", "friction force F_f = mu F_n"),
    "v_r": ("m/s", "sliding velocity used by the friction law"),
    "N_x": ("N", "horizontal bearing force at the pivot (Eq. 35); the translating follower: the guide's "
                 "reaction across it"),
    "alpha_i": ("rad", "follower angle in rigid contact (Eq. 29)"),
    "energy": ("J", "mechanical energy T + V_s + V_c (Section 5)"),
    "P_in": ("W", "power delivered by the cam drive"),
    "D_c": ("W", "power dissipated by contact damping"),
    "D_f": ("W", "power dissipated by friction"),
}
#: the follower's coordinate, by follower type (the scene option ``follower``): its name, unit and
#: meaning; the state is the coordinate and its rate, (name, name + "_dot"), the kernels' arguments
COORDINATES: dict[str, tuple[str, str, str]] = {
    "oscillating": ("alpha", "rad", "follower angle alpha, clockwise from the horizontal (Fig. 1)"),
    "translating": ("y", "m", "the face's distance y from the cam's centre E along the guide"),
}
#: the generated kernel of the static load at the cam angle theta0 (Eqs. 16-18), by follower type:
#: the moment about P, or the force along the guide; each returns (load, its derivative by the
#: coordinate, psi_i, psi_j, k_lambda)
STATIC_LOAD = {"oscillating": "static_moment", "translating": "static_force"}


def state_names(follower: str) -> tuple[str, str]:
    """The names of the state of a follower type: its coordinate and the coordinate's rate."""
    name = COORDINATES[follower][0]
    return name, name + "_dot"


#: the output of the follower's coordinate in rigid contact (Eq. 29), by follower type
RIGID_OUTPUT = {"oscillating": "alpha_i", "translating": "y_i"}


def outputs_of(follower: str) -> dict[str, tuple[str, str]]:
    """The OUTPUTS of a follower type, in their order: the translating follower's rigid-contact
    coordinate is y_i (m) where the oscillating follower's is alpha_i (rad)."""
    if follower == "oscillating":
        return dict(OUTPUTS)
    return {(RIGID_OUTPUT[follower] if k == "alpha_i" else k):
            (("m", "the follower's position in rigid contact, y = h(gamma - Theta)") if k == "alpha_i" else v)
            for k, v in OUTPUTS.items()}


#: the continuous state, in order: as a reset writes it to ``out``, as the engine samples it: the
#: follower's coordinate (alpha; y for the translating follower, COORDINATES) and its rate; the
#: index constants are positions, whatever the follower
STATE = ("alpha", "alpha_dot")
STATE_ALPHA, STATE_ALPHA_DOT = range(len(STATE))
#: the entries the generated ``jacobian`` kernel writes to ``out``, in order: the partial
#: derivatives of alpha_ddot by alpha and by alpha_dot (Eqs. 21-22), in the order of STATE
JACOBIAN = tuple(f"d_{name}" for name in STATE)
JAC_D_ALPHA, JAC_D_ALPHA_DOT = range(len(JACOBIAN))
#: the entries the generated ``surface_gradient`` kernel writes to ``out``, in order: the
#: partial derivatives of a surface's value h by the state (in the order of STATE) and the
#: total derivative by t at a fixed state (through the cam angle Theta(t)); a slip_rate surface
#: is differentiated through the alpha_ddot it contains
SURFACE_GRADIENT = JACOBIAN + ("d_t",)
GRAD_D_ALPHA, GRAD_D_ALPHA_DOT, GRAD_D_T = range(len(SURFACE_GRADIENT))
#: the entries the generated ``reset_jacobian`` kernel (a scene with resets: the rigid law's impacts)
#: writes to ``out``, in order: the derivatives of the state after reset j, (q+, q_dot+), by the state
#: before it (in the order of STATE) and by t at a fixed state: the reset's part of a saltation matrix
RESET_JACOBIAN = ("dq_dq", "dq_dq_dot", "dq_dot_dq", "dq_dot_dq_dot", "dq_dt", "dq_dot_dt")
RJ_Q_Q, RJ_Q_QD, RJ_QD_Q, RJ_QD_QD, RJ_Q_T, RJ_QD_T = range(len(RESET_JACOBIAN))
#: the entries the generated ``surface_with_rate`` kernel writes to ``out``, in order: a
#: surface's value and the value of its declared rate (the scene module's RATE_OF_SURFACE)
SURFACE_WITH_RATE = ("value", "rate")
WITH_RATE_VALUE, WITH_RATE_RATE = range(len(SURFACE_WITH_RATE))
#: the continuation parameters, in the order the generated ``field_sensitivity`` kernel writes
#: d(alpha_ddot)/d(parameter) to ``out`` (each scene: those its fields read, listed in the
#: SENSITIVITY of its companion module of variational kernels): the cam's speed (Omega_c at
#: constant speed, omega_c for the oscillating cam), the spring stiffness k_s, the
#: eccentricity e, then the damping constants
CONTINUATION_PARAMETERS = ("Omega_c", "omega_c", "k_s", "e", "zeta_A", "beta_B", "beta_C", "zeta_D", "beta_D",
                           "zeta_E", "beta_E")
#: the cam's state as the generated ``cam`` kernel and a user's cam motion return it
CAM_STATE = ("Theta", "Theta_dot", "Theta_ddot")
CAM_THETA, CAM_THETA_DOT, CAM_THETA_DDOT = range(len(CAM_STATE))
#: the power flows integrated by the energy ledger (work of the drive, contact damping, friction)
FLOWS = ("P_in", "D_c", "D_f")
