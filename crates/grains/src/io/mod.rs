//! Input and output: VTK frames, LAMMPS dumps and data files, CSV, PNG pictures.
