"""Block set-up shared by the papers' ``blocks.py`` (numpy only: embedded in the FMUs that import it)."""
from plant.pitch_axis import PitchAxisSpacecraft


def configured(block, model_name: str, description: str, defaults: dict):
    """``block`` under its FMU model name and description, with ``defaults`` set."""
    block.model_name = model_name
    block.description = description
    block.set_defaults(defaults)
    return block


def pitch_axis_plant(model_name: str, description: str, params: dict, x0, **more) -> PitchAxisSpacecraft:
    """The pitch-axis spacecraft of a parameter set (``J``, ``F``, ``omega``, ``xi``) starting from
    ``x0 = (theta, theta_dot)``; ``more`` are further defaults."""
    return configured(PitchAxisSpacecraft(n_modes=len(params["F"])), model_name, description,
                      {"J": params["J"], "F": params["F"], "omega_n": params["omega"], "zeta": params["xi"],
                       "theta_init": x0[0], "theta_dot_init": x0[1], **more})
