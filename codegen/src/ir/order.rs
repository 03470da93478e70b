//! The order of definitions: cycles found and a dependency order, both in
//! time linear per definition.

/// Whether definition `start` reaches itself through `uses`.
pub(super) fn reaches(uses: &[Vec<usize>], start: usize) -> bool {
    let mut seen = vec![false; uses.len()];
    let mut stack: Vec<usize> = uses[start].clone();
    while let Some(i) = stack.pop() {
        if i == start {
            return true;
        }
        if !std::mem::replace(&mut seen[i], true) {
            stack.extend(&uses[i]);
        }
    }
    false
}

/// Indices in an order where each comes after those it uses (Kahn's
/// algorithm); definitions on or behind a cycle come last.
pub(super) fn dependency_order(uses: &[Vec<usize>]) -> Vec<usize> {
    let mut waiting: Vec<usize> = uses.iter().map(Vec::len).collect();
    let mut users: Vec<Vec<usize>> = vec![Vec::new(); uses.len()];
    for (i, u) in uses.iter().enumerate() {
        for &j in u {
            users[j].push(i);
        }
    }
    let mut ready: Vec<usize> = (0..uses.len()).filter(|&i| waiting[i] == 0).rev().collect();
    let mut order = Vec::with_capacity(uses.len());
    while let Some(i) = ready.pop() {
        order.push(i);
        for &k in users[i].iter().rev() {
            waiting[k] -= 1;
            if waiting[k] == 0 {
                ready.push(k);
            }
        }
    }
    let placed: std::collections::HashSet<usize> = order.iter().copied().collect();
    order.extend((0..uses.len()).filter(|i| !placed.contains(i)));
    order
}
