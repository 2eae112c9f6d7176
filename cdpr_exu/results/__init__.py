"""What a run gives (the layer after ``cdpr_exu.run``): its Result, planar or spatial, and the energy
accounting."""
