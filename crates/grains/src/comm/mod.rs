//! Communication between the ranks of a distributed run.
//!
//! The engines talk to their peers only through [`Comm`]: reductions,
//! a gather of bytes to rank 0, a sparse exchange of byte buffers
//! (migrating particles, new ghost shells) and a neighbour exchange of
//! sizes known at both ends (the MD ghost refresh of every step). [`SingleProcess`] is the one-rank
//! case: the decomposed code on it is the serial run; [`ThreadComm`] runs several ranks as
//! threads of one process (the tests check decompositions with it without
//! MPI); `MpiComm` (cargo feature `mpi`) is the real thing.
//!
//! Every collective must be called by all ranks in the same order.
//! Reductions combine the ranks' values in rank order, so a sum does not
//! depend on timing (it does depend on the rank count).

pub mod codec;
#[cfg(feature = "mpi")]
pub mod mpi;
pub mod threads;

pub use codec::{Reader, Writer};
pub use threads::ThreadComm;

/// The operations a decomposed engine needs from its peers.
pub trait Comm: Send + Sync {
    /// This process's rank, 0..size.
    fn rank(&self) -> usize;
    /// The number of ranks.
    fn size(&self) -> usize;
    /// Every rank's `bytes`, in rank order, on every rank.
    fn all_gather_bytes(&self, bytes: &[u8]) -> Vec<Vec<u8>>;
    /// Every rank's `bytes`, in rank order, on rank 0 (None elsewhere).
    fn gather_bytes(&self, bytes: &[u8]) -> Option<Vec<Vec<u8>>> {
        let all = self.all_gather_bytes(bytes);
        (self.rank() == 0).then_some(all)
    }
    /// Sends `outgoing[r]` to rank r (an empty buffer sends nothing) and
    /// returns what each rank sent here, in rank order.
    fn exchange(&self, outgoing: &[Vec<u8>]) -> Vec<Vec<u8>> {
        assert_eq!(outgoing.len(), self.size(), "one buffer per rank");
        let mut w = Writer::default();
        for b in outgoing {
            w.bytes(b);
        }
        let me = self.rank();
        self.all_gather_bytes(&w.buf)
            .into_iter()
            .map(|blob| {
                let mut r = Reader::new(&blob);
                (0..=me).map(|_| r.bytes()).last().unwrap_or_default()
            })
            .collect()
    }
    /// A neighbour exchange whose sizes both ends know: sends `outgoing[r]`
    /// to every rank r in `peers` (even when empty) and receives exactly
    /// `recv_len[r]` bytes from each; the result holds them by rank (empty
    /// for ranks not in `peers`). The peer relation must be symmetric. Every
    /// rank calls it at the same point; MPI overrides it with point-to-point
    /// messages, so ranks wait only for their neighbours.
    fn exchange_with(
        &self,
        peers: &[usize],
        outgoing: &[Vec<u8>],
        recv_len: &[usize],
    ) -> Vec<Vec<u8>> {
        let got = self.exchange(outgoing);
        for &p in peers {
            assert_eq!(
                got[p].len(),
                recv_len[p],
                "neighbour message of another size"
            );
        }
        got
    }
    /// Every rank's `bytes`, all of the same length, in rank order, on every
    /// rank (one collective where [`Comm::all_gather_bytes`] needs two).
    fn all_gather_same(&self, bytes: &[u8]) -> Vec<Vec<u8>> {
        self.all_gather_bytes(bytes)
    }
    /// Element-wise sum over ranks, in place.
    fn sum_f64(&self, v: &mut [f64]) {
        self.reduce_f64(v, |a, b| a + b)
    }
    /// Element-wise maximum over ranks, in place.
    fn max_f64(&self, v: &mut [f64]) {
        self.reduce_f64(v, f64::max)
    }
    /// Element-wise minimum over ranks, in place.
    fn min_f64(&self, v: &mut [f64]) {
        self.reduce_f64(v, f64::min)
    }
    /// Element-wise sum over ranks, in place (exact).
    fn sum_u64(&self, v: &mut [u64]) {
        let mut w = Writer::default();
        v.iter().for_each(|&x| w.u64(x));
        let all = self.all_gather_bytes(&w.buf);
        v.fill(0);
        for blob in &all {
            let mut r = Reader::new(blob);
            v.iter_mut().for_each(|x| *x += r.u64());
        }
    }
    /// Waits until every rank got here.
    fn barrier(&self) {
        self.all_gather_bytes(&[]);
    }
    /// Rank-ordered reduction of f64 vectors through a gather.
    #[doc(hidden)]
    fn reduce_f64(&self, v: &mut [f64], op: fn(f64, f64) -> f64) {
        let mut w = Writer::default();
        v.iter().for_each(|&x| w.f64(x));
        let all = self.all_gather_bytes(&w.buf);
        for (k, blob) in all.iter().enumerate() {
            let mut r = Reader::new(blob);
            for x in v.iter_mut() {
                let y = r.f64();
                *x = if k == 0 { y } else { op(*x, y) };
            }
        }
    }
}

/// One rank: the serial run.
#[derive(Clone, Copy, Debug, Default)]
pub struct SingleProcess;

impl Comm for SingleProcess {
    fn rank(&self) -> usize {
        0
    }
    fn size(&self) -> usize {
        1
    }
    fn all_gather_bytes(&self, bytes: &[u8]) -> Vec<Vec<u8>> {
        vec![bytes.to_vec()]
    }
    fn exchange(&self, outgoing: &[Vec<u8>]) -> Vec<Vec<u8>> {
        outgoing.to_vec()
    }
    fn reduce_f64(&self, _v: &mut [f64], _op: fn(f64, f64) -> f64) {}
    fn sum_u64(&self, _v: &mut [u64]) {}
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn collectives_on_four_thread_ranks() {
        let out = ThreadComm::run(4, |c| {
            let r = c.rank() as f64;
            let mut s = [r, -r];
            c.sum_f64(&mut s);
            let mut m = [r];
            c.max_f64(&mut m);
            let mut n = [r];
            c.min_f64(&mut n);
            let mut u = [c.rank() as u64 + 1];
            c.sum_u64(&mut u);
            // Rank r sends "r->d" to every d != r.
            let send: Vec<Vec<u8>> = (0..c.size())
                .map(|d| {
                    if d == c.rank() {
                        Vec::new()
                    } else {
                        format!("{}->{d}", c.rank()).into_bytes()
                    }
                })
                .collect();
            let got = c.exchange(&send);
            let g = c.gather_bytes(&[c.rank() as u8]);
            (s, m[0], n[0], u[0], got, g)
        });
        for (rank, (s, m, n, u, got, g)) in out.into_iter().enumerate() {
            assert_eq!(s, [6.0, -6.0]);
            assert_eq!((m, n, u), (3.0, 0.0, 10));
            for (src, b) in got.iter().enumerate() {
                let want = if src == rank {
                    String::new()
                } else {
                    format!("{src}->{rank}")
                };
                assert_eq!(String::from_utf8(b.clone()).unwrap(), want);
            }
            assert_eq!(g.is_some(), rank == 0);
            if let Some(g) = g {
                assert_eq!(g, vec![vec![0], vec![1], vec![2], vec![3]]);
            }
        }
    }

    #[test]
    fn neighbour_exchange_and_fixed_gather_on_a_ring_of_three() {
        let out = ThreadComm::run(3, |c| {
            let (r, n) = (c.rank(), c.size());
            let peers = [(r + n - 1) % n, (r + 1) % n];
            let mut send = vec![Vec::new(); n];
            let mut len = vec![0; n];
            for &p in &peers {
                // r sends r + 1 bytes of value r to each neighbour.
                send[p] = vec![r as u8; r + 1];
                len[p] = p + 1;
            }
            let got = c.exchange_with(&peers, &send, &len);
            (got, c.all_gather_same(&[r as u8, 7]))
        });
        for (r, (got, all)) in out.into_iter().enumerate() {
            for (p, b) in got.iter().enumerate() {
                let want = if p == r { vec![] } else { vec![p as u8; p + 1] };
                assert_eq!(b, &want);
            }
            assert_eq!(all, vec![vec![0, 7], vec![1, 7], vec![2, 7]]);
        }
    }

    #[test]
    fn single_process_is_the_identity() {
        let c = SingleProcess;
        let mut v = [1.5, 2.0];
        c.sum_f64(&mut v);
        assert_eq!(v, [1.5, 2.0]);
        assert_eq!(c.exchange(&[b"x".to_vec()]), vec![b"x".to_vec()]);
        assert_eq!(c.gather_bytes(b"ab"), Some(vec![b"ab".to_vec()]));
    }
}
