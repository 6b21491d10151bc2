"""The paper's experiments: one frozen preset per experiment, run by one runner."""
