"""Design-load campaigns: a scene run over a table of load cases (`campaign`, `cases`,
`store`, the command line's `command`), and the reductions of a case to what a design
code asks for (fatigue damage by rainflow counting and T–N curves, `fatigue`)."""
