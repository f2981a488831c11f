"""Design-load campaigns: the reductions of load cases to what a design code asks for
(fatigue damage by rainflow counting and T–N curves)."""
