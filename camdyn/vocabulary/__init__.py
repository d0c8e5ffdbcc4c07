"""The vocabulary derive/ and the runtime share, SymPy-free (the contract between them): the
scene options (scenes), the automaton's names and the kernels' result layouts (names), and every
constant of the model with its unit, meaning and valid range (parameters)."""
from __future__ import annotations

from .names import (DAMPING_PHASES, SLIP_STATES, mode_name, TRANSITION, TRANSITION_SOURCE, TRANSITION_SURFACE,
                    TRANSITION_DIRECTION, TRANSITION_TARGETS, TRANSITION_RESET, SURFACES, OUTPUTS, STATE,
                    STATE_ALPHA, STATE_ALPHA_DOT, JACOBIAN, JAC_D_ALPHA, JAC_D_ALPHA_DOT, SURFACE_GRADIENT,
                    GRAD_D_ALPHA, GRAD_D_ALPHA_DOT, GRAD_D_T, SURFACE_WITH_RATE, WITH_RATE_VALUE, WITH_RATE_RATE,
                    CONTINUATION_PARAMETERS, CAM_STATE, CAM_THETA, CAM_THETA_DOT, CAM_THETA_DDOT, FLOWS,
                    COORDINATES, STATIC_LOAD, RIGID_OUTPUT, state_names, outputs_of, RESET_JACOBIAN, RJ_Q_Q,
                    RJ_Q_QD, RJ_QD_Q, RJ_QD_QD, RJ_Q_T, RJ_QD_T)
from .scenes import (CONTACT_LAWS, DAMPING_MODELS, FRICTION_MODELS, MOTIONS, MODELS, SLIDING_VELOCITY_FORMS,
                     DAMPING_SIGNS, DAMPING_SWITCHES, FOLLOWERS, RESPONSES, FACES, ECCENTRIC, PROFILES, OPTIONS, RUNTIME_OPTIONS, SLUG_SUFFIXES,
                     SWITCHED_DAMPING, SceneOptionError, SceneSpec, combination_problem, DEFAULTS)

__all__ = ["RESET_JACOBIAN", "RJ_Q_Q", "RJ_Q_QD", "RJ_QD_Q", "RJ_QD_QD", "RJ_Q_T", "RJ_QD_T", "COORDINATES", "STATIC_LOAD", "RIGID_OUTPUT", "state_names", "outputs_of", "CAM_STATE", "CAM_THETA", "CAM_THETA_DDOT", "CAM_THETA_DOT", "CONTACT_LAWS", "CONTINUATION_PARAMETERS",
           "DAMPING_MODELS", "DAMPING_PHASES", "DAMPING_SIGNS", "DAMPING_SWITCHES", "DEFAULTS", "ECCENTRIC", "FLOWS", "FOLLOWERS",
           "FACES", "FRICTION_MODELS", "RESPONSES", "GRAD_D_ALPHA", "GRAD_D_ALPHA_DOT", "GRAD_D_T", "JACOBIAN", "JAC_D_ALPHA",
           "JAC_D_ALPHA_DOT", "MODELS", "MOTIONS", "OPTIONS", "OUTPUTS", "PROFILES", "RUNTIME_OPTIONS", "SLIDING_VELOCITY_FORMS",
           "SLIP_STATES", "SLUG_SUFFIXES", "STATE", "STATE_ALPHA", "STATE_ALPHA_DOT", "SURFACES", "SURFACE_GRADIENT",
           "SURFACE_WITH_RATE", "SWITCHED_DAMPING", "SceneOptionError", "SceneSpec", "TRANSITION",
           "TRANSITION_DIRECTION", "TRANSITION_RESET", "TRANSITION_SOURCE", "TRANSITION_SURFACE",
           "TRANSITION_TARGETS", "WITH_RATE_RATE", "WITH_RATE_VALUE", "combination_problem", "mode_name"]
