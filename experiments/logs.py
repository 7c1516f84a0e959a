"""The one-line loaders of the logs, at a short path (experiments/analysis/logs.py documents
every column):

    from experiments.logs import read_log, read_batch_logs
    log = read_log(TRIAL_DIR)                        # a trial's iterations, one row each
    words = read_log(TRIAL_DIR, kind="words")        # best distance to each word, every 100
    batch = read_batch_logs(BATCH_DIR, "iterations")  # every trial of a batch, in one frame
"""

from experiments.analysis.logs import SOURCE_COLUMNS, read_batch_logs, read_log

__all__ = ["SOURCE_COLUMNS", "read_batch_logs", "read_log"]
