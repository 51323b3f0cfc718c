"""wobjcal web UI (viser): a thin layer that turns browser events into planner/calib calls."""
