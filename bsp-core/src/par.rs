//! Parallel loops whose scheduling is compiled once.
//!
//! Every rayon call site with its own closure instantiates rayon's whole
//! splitting and job machinery again, in every crate that uses it: about a
//! third of the workspace's optimised code was such copies, and most of the
//! release build's time goes to optimising code. The loops here hand the
//! work to one non-generic rayon loop through a `dyn` closure, so a call
//! site costs a small wrapper. They run on the current rayon pool, and
//! their results come back in index order whatever the scheduling, so an
//! output is the same for every number of threads.
//!
//! Each loop cuts `0..n` into runs of consecutive indices (enough for the
//! pool to balance uneven work) and calls the closure once per index or
//! per run; a dynamic call per run is nothing beside the work of a run of
//! faces, cells or rows.

use rayon::prelude::*;
use std::ops::Range;
use std::sync::Mutex;
use std::sync::atomic::{AtomicUsize, Ordering};

/// How many runs `0..n` is cut into: at most 64 a thread, so that uneven
/// runs balance (rayon splits the runs among the threads as they steal
/// work), and never more than `n`.
fn run_count(n: usize) -> usize {
    n.min(64 * rayon::current_num_threads().max(1))
}

/// The `k`-th of `runs` nearly equal runs of `0..n`.
fn run(n: usize, runs: usize, k: usize) -> Range<usize> {
    (k * n / runs)..((k + 1) * n / runs)
}

/// Calls `f` once for each run of a cut of `0..n` into consecutive runs,
/// in parallel. The one place that instantiates rayon's loop.
fn each_run(n: usize, f: &(dyn Fn(usize, Range<usize>) + Sync)) {
    let runs = run_count(n);
    if runs <= 1 {
        if n > 0 {
            f(0, 0..n);
        }
        return;
    }
    (0..runs)
        .into_par_iter()
        .for_each(|k| f(k, run(n, runs, k)));
}

/// `f(i)` for every `i` in `0..n`, in parallel.
pub fn for_each(n: usize, f: impl Fn(usize) + Sync) {
    each_run(n, &|_, r| r.for_each(&f));
}

/// The runs' values `f(range)` for a cut of `0..n` into consecutive
/// ranges, in the ranges' order: a parallel fold whose partial results the
/// caller combines (the cut depends on the number of threads, so combine
/// them with an associative and commutative operation, or in order with an
/// exact one).
pub fn fold_runs<A: Send>(n: usize, f: impl Fn(Range<usize>) -> A + Sync) -> Vec<A> {
    fold_numbered_runs(n, |_, r| f(r))
}

/// [`fold_runs`], telling `f` the number of its run too.
fn fold_numbered_runs<A: Send>(n: usize, f: impl Fn(usize, Range<usize>) -> A + Sync) -> Vec<A> {
    let runs = run_count(n);
    let slots = empty_slots(runs);
    each_run(n, &|k, r| fill(&slots[k], f(k, r)));
    filled(slots)
}

/// `n` empty places for values made on the pool's threads.
fn empty_slots<A>(n: usize) -> Vec<Mutex<Option<A>>> {
    (0..n).map(|_| Mutex::new(None)).collect()
}

/// Puts `a` in its place.
fn fill<A>(slot: &Mutex<Option<A>>, a: A) {
    *slot.lock().unwrap_or_else(|e| e.into_inner()) = Some(a);
}

/// The values of places that a loop filled, in order.
fn filled<A>(slots: Vec<Mutex<Option<A>>>) -> Vec<A> {
    (slots.into_iter())
        .map(|s| (s.into_inner().unwrap_or_else(|e| e.into_inner())).expect("every place filled"))
        .collect()
}

/// `[f(0), f(1), …, f(n - 1)]`, computed in parallel.
pub fn map<T: Send>(n: usize, f: impl Fn(usize) -> T + Sync) -> Vec<T> {
    let parts = fold_runs(n, |r| r.map(&f).collect::<Vec<T>>());
    let mut out = Vec::with_capacity(n);
    for p in parts {
        out.extend(p);
    }
    out
}

/// [`map`] with each value written by its thread straight into its place
/// in the output, where [`map`] gathers the runs' values and copies them
/// on one thread: for large values, whose copy (and the first touch of the
/// output's pages) would otherwise be a serial phase. Compiles rayon's
/// collection once for each `T`.
pub fn map_placed<T: Send>(n: usize, f: impl Fn(usize) -> T + Sync) -> Vec<T> {
    placed(n, &f)
}

fn placed<T: Send>(n: usize, f: &(dyn Fn(usize) -> T + Sync)) -> Vec<T> {
    let mut out = Vec::new();
    let min = n.div_ceil(run_count(n).max(1)).max(1);
    (0..n)
        .into_par_iter()
        .with_min_len(min)
        .map(f)
        .collect_into_vec(&mut out);
    out
}

/// `[f(0)?, f(1)?, …]`, computed in parallel: the values, or the error of
/// the first index that failed (the same error for every number of
/// threads).
pub fn try_map<T: Send, E: Send>(
    n: usize,
    f: impl Fn(usize) -> Result<T, E> + Sync,
) -> Result<Vec<T>, E> {
    map(n, f).into_iter().collect()
}

/// `[f(0), f(1), …]`, computed in parallel and started in the order of
/// `costs`, the largest first (ties by index): for a few items of uneven
/// and roughly known cost, where an item started last and large keeps one
/// thread busy after the others have run out of work. Each thread takes
/// the next item of that order when it is free; the values come back in
/// index order.
pub fn map_largest_first<T: Send>(costs: &[u64], f: impl Fn(usize) -> T + Sync) -> Vec<T> {
    let n = costs.len();
    let mut order: Vec<usize> = (0..n).collect();
    order.sort_by(|&a, &b| costs[b].cmp(&costs[a]).then(a.cmp(&b)));
    let next = AtomicUsize::new(0);
    let slots = empty_slots(n);
    // every call takes one item of the order, whichever index the loop
    // gave it
    for_each(n, |_| {
        let i = order[next.fetch_add(1, Ordering::Relaxed)];
        fill(&slots[i], f(i));
    });
    filled(slots)
}

/// `f` applied to every item of `items`, moved in, in parallel, in order.
pub fn map_vec<S: Send, T: Send>(items: Vec<S>, f: impl Fn(S) -> T + Sync) -> Vec<T> {
    let n = items.len();
    let runs = run_count(n);
    let mut items = items.into_iter();
    let parts: Vec<Mutex<Vec<S>>> = (0..runs)
        .map(|k| Mutex::new(items.by_ref().take(run(n, runs, k).len()).collect()))
        .collect();
    let outs = fold_numbered_runs(n, |k, _| {
        let mut part = parts[k].lock().unwrap_or_else(|e| e.into_inner());
        std::mem::take(&mut *part)
            .into_iter()
            .map(&f)
            .collect::<Vec<T>>()
    });
    outs.into_iter().flatten().collect()
}

/// `f` applied to every item of `items`, in parallel, in order.
pub fn map_slice<S: Sync, T: Send>(items: &[S], f: impl Fn(&S) -> T + Sync) -> Vec<T> {
    map(items.len(), |i| f(&items[i]))
}

/// The items `i` of `0..n` (in order) for which `f(i)` is `Some`, computed
/// in parallel.
pub fn filter_map<T: Send>(n: usize, f: impl Fn(usize) -> Option<T> + Sync) -> Vec<T> {
    let parts = fold_runs(n, |r| r.filter_map(&f).collect::<Vec<T>>());
    parts.into_iter().flatten().collect()
}

/// The concatenation, in order, of `f(0), f(1), …`, computed in parallel.
pub fn flat_map<T: Send>(n: usize, f: impl Fn(usize) -> Vec<T> + Sync) -> Vec<T> {
    let parts = fold_runs(n, |r| r.flat_map(&f).collect::<Vec<T>>());
    parts.into_iter().flatten().collect()
}

/// `f(i, &mut items[i])` for every item, in parallel.
pub fn for_each_mut<T: Send>(items: &mut [T], f: impl Fn(usize, &mut T) + Sync) {
    let runs = run_count(items.len());
    let n = items.len();
    // the runs as disjoint mutable slices, each behind its own lock (taken
    // once, by the one run that owns it)
    let mut rest = items;
    let mut parts = Vec::with_capacity(runs);
    for k in 0..runs {
        let r = run(n, runs, k);
        let (head, tail) = rest.split_at_mut(r.len());
        parts.push(Mutex::new((r.start, head)));
        rest = tail;
    }
    each_run(n, &|k, _| {
        let mut part = parts[k].lock().unwrap_or_else(|e| e.into_inner());
        let (start, slice) = &mut *part;
        for (j, x) in slice.iter_mut().enumerate() {
            f(*start + j, x);
        }
    });
}

/// `[f(0, chunk 0), f(1, chunk 1), …]` for the consecutive chunks of
/// `items` of `chunk` items each (the last may be shorter), in parallel.
pub fn map_chunks_mut<T: Send, R: Send>(
    items: &mut [T],
    chunk: usize,
    f: impl Fn(usize, &mut [T]) -> R + Sync,
) -> Vec<R> {
    let parts: Vec<Mutex<(&mut [T], Option<R>)>> = items
        .chunks_mut(chunk.max(1))
        .map(|c| Mutex::new((c, None)))
        .collect();
    for_each(parts.len(), |k| {
        let mut part = parts[k].lock().unwrap_or_else(|e| e.into_inner());
        let (slice, out) = &mut *part;
        *out = Some(f(k, slice));
    });
    parts
        .into_iter()
        .map(|p| {
            p.into_inner()
                .unwrap_or_else(|e| e.into_inner())
                .1
                .expect("every chunk ran")
        })
        .collect()
}

/// `(a(), b())`, possibly in parallel: `rayon::join` through one
/// non-generic instantiation.
pub fn join<A: Send, B: Send>(
    a: impl FnOnce() -> A + Send,
    b: impl FnOnce() -> B + Send,
) -> (A, B) {
    let (mut fa, mut fb) = (Some(a), Some(b));
    let (mut ra, mut rb) = (None, None);
    join_dyn(&mut || ra = fa.take().map(|f| f()), &mut || {
        rb = fb.take().map(|f| f())
    });
    (ra.expect("a ran"), rb.expect("b ran"))
}

fn join_dyn(a: &mut (dyn FnMut() + Send), b: &mut (dyn FnMut() + Send)) {
    rayon::join(a, b);
}

#[cfg(test)]
mod tests {
    use super::*;

    fn pools() -> Vec<rayon::ThreadPool> {
        [1, 2, 3, 7]
            .iter()
            .map(|&t| {
                rayon::ThreadPoolBuilder::new()
                    .num_threads(t)
                    .build()
                    .unwrap()
            })
            .collect()
    }

    #[test]
    fn the_largest_start_first() {
        // one thread: the calls come one after the other, in the order
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(1)
            .build()
            .unwrap();
        let started = Mutex::new(Vec::new());
        let costs = [3, 9, 1, 9, 4];
        let out = pool.install(|| {
            map_largest_first(&costs, |i| {
                started.lock().unwrap().push(i);
                10 * i
            })
        });
        assert_eq!(out, [0, 10, 20, 30, 40]);
        assert_eq!(started.into_inner().unwrap(), [1, 3, 4, 0, 2]);
    }

    #[test]
    fn loops_give_the_sequential_answer_for_every_pool() {
        for pool in pools() {
            pool.install(|| {
                for n in [0usize, 1, 2, 5, 16, 17, 100, 1000] {
                    let want: Vec<usize> = (0..n).map(|i| i * i).collect();
                    assert_eq!(map(n, |i| i * i), want);
                    let items: Vec<usize> = (0..n).collect();
                    assert_eq!(map_slice(&items, |&i| i * i), want);
                    assert_eq!(map_vec(items.clone(), |i| i * i), want);
                    let first_bad = try_map(n, |i| if i % 7 == 6 { Err(i) } else { Ok(i) });
                    assert_eq!(first_bad, if n > 6 { Err(6) } else { Ok(items.clone()) });
                    let odd: Vec<usize> = (0..n).filter(|i| i % 2 == 1).collect();
                    assert_eq!(filter_map(n, |i| (i % 2 == 1).then_some(i)), odd);
                    let costs: Vec<u64> = (0..n as u64).map(|i| (i * 7) % 5).collect();
                    assert_eq!(map_largest_first(&costs, |i| i * i), want);
                    let flat: Vec<usize> = (0..n).flat_map(|i| vec![i; i % 3]).collect();
                    assert_eq!(flat_map(n, |i| vec![i; i % 3]), flat);
                    let sums = fold_runs(n, |r| r.sum::<usize>());
                    assert_eq!(sums.iter().sum::<usize>(), (0..n).sum::<usize>());
                    let mut v = vec![0usize; n];
                    for_each_mut(&mut v, |i, x| *x = 3 * i);
                    assert_eq!(v, (0..n).map(|i| 3 * i).collect::<Vec<_>>());
                    let seen: Vec<Mutex<u32>> = (0..n).map(|_| Mutex::new(0)).collect();
                    for_each(n, |i| *seen[i].lock().unwrap() += 1);
                    assert!(seen.iter().all(|c| *c.lock().unwrap() == 1));
                    assert_eq!(join(|| n + 1, || vec![n]), (n + 1, vec![n]));
                    let mut w = vec![1usize; n];
                    let firsts = map_chunks_mut(&mut w, 3, |k, c| {
                        c.iter_mut().for_each(|x| *x += k);
                        c.len()
                    });
                    assert_eq!(
                        firsts,
                        (0..n.div_ceil(3))
                            .map(|k| (n - 3 * k).min(3))
                            .collect::<Vec<_>>()
                    );
                    assert_eq!(w, (0..n).map(|i| 1 + i / 3).collect::<Vec<_>>());
                }
            });
        }
    }
}
