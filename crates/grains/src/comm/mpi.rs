//! The system MPI through rsmpi (cargo feature `mpi`). Launch with
//! `mpirun -np N grains run scenario.toml`.

use super::Comm;
use mpi::collective::SystemOperation;
use mpi::datatype::{Partition, PartitionMut};
use mpi::topology::SimpleCommunicator;
use mpi::traits::*;
use mpi::Count;

/// MPI_COMM_WORLD of an initialized MPI environment.
pub struct MpiComm {
    // Finalizes MPI when dropped: keep it alive for the whole run.
    _universe: mpi::environment::Universe,
    world: SimpleCommunicator,
}

// SAFETY: the collectives are only called by the thread that runs the step,
// one at a time
// (MPI initialized with threading "serialized": the run may sit on a rayon
// worker, `crate::parallel::on_pool`); the parallel loops never touch it.
unsafe impl Send for MpiComm {}
unsafe impl Sync for MpiComm {}

impl MpiComm {
    /// Initializes MPI; None when it was initialized already.
    pub fn init() -> Option<Self> {
        let (universe, _) = mpi::initialize_with_threading(mpi::Threading::Serialized)?;
        let world = universe.world();
        Some(Self {
            _universe: universe,
            world,
        })
    }
}

fn displacements(counts: &[Count]) -> Vec<Count> {
    counts
        .iter()
        .scan(0, |acc, &c| {
            let d = *acc;
            *acc += c;
            Some(d)
        })
        .collect()
}

fn split(buf: &[u8], counts: &[Count]) -> Vec<Vec<u8>> {
    let mut at = 0;
    counts
        .iter()
        .map(|&c| {
            let s = buf[at..at + c as usize].to_vec();
            at += c as usize;
            s
        })
        .collect()
}

/// Open MPI's MPI_IN_PLACE is the address 1, which is also where Rust puts
/// an empty `Vec<u8>`: empty buffers must point somewhere real.
static PAD: [u8; 1] = [0];

fn real(b: &[u8]) -> &[u8] {
    if b.is_empty() {
        &PAD[..0]
    } else {
        b
    }
}

/// A receive buffer of `n` bytes with a real address even when n = 0.
fn recv_buffer(n: usize) -> Vec<u8> {
    let mut v = vec![0u8; n.max(1)];
    v.truncate(n);
    v
}

fn count(n: usize) -> Count {
    Count::try_from(n).expect("an MPI message over 2 GiB: use more ranks")
}

impl Comm for MpiComm {
    fn rank(&self) -> usize {
        self.world.rank() as usize
    }
    fn size(&self) -> usize {
        self.world.size() as usize
    }
    fn all_gather_bytes(&self, bytes: &[u8]) -> Vec<Vec<u8>> {
        let mut counts = vec![0 as Count; self.size()];
        self.world
            .all_gather_into(&count(bytes.len()), &mut counts[..]);
        let displs = displacements(&counts);
        let total: usize = counts.iter().map(|&c| c as usize).sum();
        let mut buf = recv_buffer(total);
        {
            let mut part = PartitionMut::new(&mut buf[..], &counts[..], &displs[..]);
            self.world.all_gather_varcount_into(real(bytes), &mut part);
        }
        split(&buf, &counts)
    }
    fn gather_bytes(&self, bytes: &[u8]) -> Option<Vec<Vec<u8>>> {
        let root = self.world.process_at_rank(0);
        let n = count(bytes.len());
        if self.rank() != 0 {
            root.gather_into(&n);
            root.gather_varcount_into(real(bytes));
            return None;
        }
        let mut counts = vec![0 as Count; self.size()];
        root.gather_into_root(&n, &mut counts[..]);
        let displs = displacements(&counts);
        let total: usize = counts.iter().map(|&c| c as usize).sum();
        let mut buf = recv_buffer(total);
        {
            let mut part = PartitionMut::new(&mut buf[..], &counts[..], &displs[..]);
            root.gather_varcount_into_root(real(bytes), &mut part);
        }
        Some(split(&buf, &counts))
    }
    fn exchange(&self, outgoing: &[Vec<u8>]) -> Vec<Vec<u8>> {
        assert_eq!(outgoing.len(), self.size(), "one buffer per rank");
        let send_counts: Vec<Count> = outgoing.iter().map(|b| count(b.len())).collect();
        let mut recv_counts = vec![0 as Count; self.size()];
        self.world
            .all_to_all_into(&send_counts[..], &mut recv_counts[..]);
        let send: Vec<u8> = outgoing.concat();
        let sd = displacements(&send_counts);
        let rd = displacements(&recv_counts);
        let total: usize = recv_counts.iter().map(|&c| c as usize).sum();
        let mut buf = recv_buffer(total);
        {
            let part = Partition::new(real(&send), &send_counts[..], &sd[..]);
            let mut rpart = PartitionMut::new(&mut buf[..], &recv_counts[..], &rd[..]);
            self.world.all_to_all_varcount_into(&part, &mut rpart);
        }
        split(&buf, &recv_counts)
    }
    fn exchange_with(
        &self,
        peers: &[usize],
        outgoing: &[Vec<u8>],
        recv_len: &[usize],
    ) -> Vec<Vec<u8>> {
        let mut got = vec![Vec::new(); self.size()];
        let mut bufs: Vec<Vec<u8>> = peers.iter().map(|&p| recv_buffer(recv_len[p])).collect();
        mpi::request::scope(|scope| {
            let mut recvs = Vec::with_capacity(peers.len());
            for (&p, buf) in peers.iter().zip(bufs.iter_mut()) {
                let from = self.world.process_at_rank(p as i32);
                recvs.push(from.immediate_receive_into(scope, &mut buf[..]));
            }
            let mut sends = Vec::with_capacity(peers.len());
            for &p in peers {
                let to = self.world.process_at_rank(p as i32);
                sends.push(to.immediate_send(scope, real(&outgoing[p])));
            }
            for r in recvs {
                r.wait();
            }
            for r in sends {
                r.wait();
            }
        });
        for (&p, buf) in peers.iter().zip(bufs) {
            got[p] = buf;
        }
        got
    }
    fn all_gather_same(&self, bytes: &[u8]) -> Vec<Vec<u8>> {
        let mut buf = recv_buffer(bytes.len() * self.size());
        self.world.all_gather_into(real(bytes), &mut buf[..]);
        buf.chunks(bytes.len().max(1))
            .map(<[u8]>::to_vec)
            .chain(std::iter::repeat(Vec::new()))
            .take(self.size())
            .collect()
    }
    fn sum_u64(&self, v: &mut [u64]) {
        let mut out = vec![0u64; v.len()];
        self.world
            .all_reduce_into(&v[..], &mut out[..], SystemOperation::sum());
        v.copy_from_slice(&out);
    }
    fn max_f64(&self, v: &mut [f64]) {
        let mut out = vec![0.0; v.len()];
        self.world
            .all_reduce_into(&v[..], &mut out[..], SystemOperation::max());
        v.copy_from_slice(&out);
    }
    fn min_f64(&self, v: &mut [f64]) {
        let mut out = vec![0.0; v.len()];
        self.world
            .all_reduce_into(&v[..], &mut out[..], SystemOperation::min());
        v.copy_from_slice(&out);
    }
    fn barrier(&self) {
        self.world.barrier();
    }
}

impl MpiComm {
    /// Ends every rank of the job with `code`.
    pub fn abort(&self, code: i32) -> ! {
        self.world.abort(code)
    }
}
