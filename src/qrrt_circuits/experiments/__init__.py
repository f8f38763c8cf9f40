"""Reproductions of the paper's figures and tables, one module per experiment, and a runner that
writes records.csv (one row per trial), summary.json and figures, and resumes interrupted runs."""

from .catalog import EXPERIMENTS
from .runner import read_records, run_experiment

__all__ = ["EXPERIMENTS", "read_records", "run_experiment"]
