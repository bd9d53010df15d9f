"""The simulated world of host servo --sim: scene, robot, renderer, fault models, trials."""
