"""Pages and figures of batches, beside the paper's numbers (read only)."""
