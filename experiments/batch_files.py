"""Every file a batch directory holds of its own, by name, in one place: its record, its
workers' tokens and the pages written about it. A batch directory also holds one trial
directory per trial, whose files are the trial's (experiments/trial_dir/layout.py names them):
nothing here is a trial's.
"""

from __future__ import annotations

# What a batch is: its spec as `playroom batch` last ran it (experiments/batches/spec.py).
BATCH_FILE = "batch.json"
# What a batch's submitter writes into the batch directory for its workers to read back (the
# same path on a shared filesystem), one per run, removed when the run ends: NAME.format(run).
WORKER_TOKEN_FILE = ".workers-{}.token"

# Pages about a batch ------------------------------------------------------------------------
REPORT_FILE = "report.html"
COMPARISON_FILE = "comparison.html"
ABLATION_TABLE_FILE = "ablations.md"
ABLATION_CSV_FILE = "ablations.csv"
ABLATION_FIGURE_FILE = "ablations.png"
# The numbers a report or comparison page shows, machine-readable, written with the page
# (experiments/report/summary.py): nested JSON, and the same numbers as one long CSV table.
SUMMARY_JSON_FILE = "summary.json"
SUMMARY_CSV_FILE = "summary.csv"
