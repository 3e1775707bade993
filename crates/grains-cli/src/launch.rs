//! How the process was launched: alone, or as one rank of `mpirun` (with
//! the cargo feature `mpi`). MPI is initialized only when the launcher's
//! environment says so, so a plain `grains run` never touches MPI.

use grains::comm::Comm;

/// The ranks of this run: None for a plain process.
pub struct Ranks {
    #[cfg(feature = "mpi")]
    comm: Option<grains::comm::mpi::MpiComm>,
}

/// Variables that Open MPI, MPICH and Slurm's PMI set in each rank.
#[cfg(feature = "mpi")]
const LAUNCHER_VARS: [&str; 3] = ["OMPI_COMM_WORLD_SIZE", "PMI_SIZE", "PMIX_RANK"];

impl Ranks {
    pub fn detect() -> Self {
        #[cfg(feature = "mpi")]
        {
            let launched = LAUNCHER_VARS.iter().any(|v| std::env::var_os(v).is_some());
            Self {
                comm: launched.then(grains::comm::mpi::MpiComm::init).flatten(),
            }
        }
        #[cfg(not(feature = "mpi"))]
        Self {}
    }

    /// The communicator when there is more than one rank.
    pub fn several(&self) -> Option<&dyn Comm> {
        #[cfg(feature = "mpi")]
        if let Some(c) = &self.comm {
            if c.size() > 1 {
                return Some(c);
            }
        }
        None
    }

    /// Whether this process reports errors that every rank meets alike
    /// (bad input): rank 0, or a plain process.
    pub fn reports_input_errors(&self) -> bool {
        self.several().is_none_or(|c| c.rank() == 0)
    }

    /// Ends every rank with `code` (an error on one rank would leave the
    /// others waiting in a collective).
    pub fn abort(&self, code: u8) {
        #[cfg(feature = "mpi")]
        if let Some(c) = &self.comm {
            if c.size() > 1 {
                c.abort(code as i32);
            }
        }
        let _ = code;
    }
}
