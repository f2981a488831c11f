"""The model of a cable network: its graph and lines, tension laws, prescribed motions,
state, and the static indexing and reach that follow from its topology."""
