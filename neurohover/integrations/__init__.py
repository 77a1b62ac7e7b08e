"""Adapters to other libraries' interfaces (optional extras; each module imports its library)."""

#: The algorithms a saved Stable-Baselines3 or sb3-contrib model may be of, by RL Zoo's names: (package, class).
#: Here, not in :mod:`.sb3`, so that the command line lists them without importing SB3.
SB3_ALGORITHMS: dict[str, tuple[str, str]] = {
    "ppo": ("stable_baselines3", "PPO"),
    "sac": ("stable_baselines3", "SAC"),
    "td3": ("stable_baselines3", "TD3"),
    "a2c": ("stable_baselines3", "A2C"),
    "ppo_lstm": ("sb3_contrib", "RecurrentPPO"),
    "tqc": ("sb3_contrib", "TQC"),
    "trpo": ("sb3_contrib", "TRPO"),
    "crossq": ("sb3_contrib", "CrossQ"),
    "ars": ("sb3_contrib", "ARS"),
}
