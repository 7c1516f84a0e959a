"""A deep reinforcement-learning baseline against the study's learner on the same test:
stable-baselines3's SAC with hindsight relabelling (HerReplayBuffer), every default kept, trained
on sim/envs' toy-goal environments, then tested by the project's own measure exactly as a
trial's final agent is (experiments/measure/trial_evaluation.py `measured`). Its library is the
optional `rl` extra, imported only when a baseline is trained or loaded (training.py).
docs/rl-baseline.md has the protocol."""
