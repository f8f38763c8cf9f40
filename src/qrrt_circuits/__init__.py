"""qrrt_circuits: quantum-search sampling-based motion planners (q-RRT, Pq-RRT, QDA)."""
