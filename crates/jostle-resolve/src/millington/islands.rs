//! Contact islands and the body → contacts adjacency of one step.
//!
//! Two contacts interact in the passes only through a body they share, and the static entry
//! (or any immovable body) is never moved, so it connects nothing: a union-find over the
//! moving bodies splits the contacts into independent islands, solved one after the other
//! with their own pick budgets. The adjacency lists, per moving body, the contacts that touch
//! it, so a pick re-keys only those.
//!
//! Everything is rebuilt each step into reused buffers; order is deterministic: islands are
//! ordered by their lowest contact index, and contacts within an island and within an
//! adjacency list by ascending index.

use super::change::NO_BODY;
use super::prepare::PreparedContact;
use crate::union_find::UnionFind;

/// Contacts grouped by island, and the adjacency of moving bodies, in CSR form.
#[derive(Clone, Debug, Default)]
pub struct Islands {
    /// Contact indices, island by island, ascending within each island.
    order: Vec<u32>,
    /// `order[starts[i]..starts[i + 1]]` is island i.
    starts: Vec<u32>,
    /// `adj_contacts[adj_starts[b]..adj_starts[b + 1]]` are the contacts touching body b.
    adj_starts: Vec<u32>,
    adj_contacts: Vec<u32>,
    /// Union-find over the bodies (scratch).
    sets: UnionFind,
    /// Island of each union-find root, or `NO_BODY` (scratch).
    island_of_root: Vec<u32>,
    /// Island of each contact, or `NO_BODY` when it takes part in nothing (scratch).
    island_of_contact: Vec<u32>,
    /// Contacts per island, then per-island or per-body write cursors (scratch).
    counts: Vec<u32>,
    cursor: Vec<u32>,
}

impl Islands {
    /// Rebuilds islands and adjacency for `contacts` over `body_count` bodies. Contacts with
    /// no moving side belong to no island.
    pub fn build(&mut self, contacts: &[PreparedContact], body_count: usize) {
        self.sets.reset(body_count);
        for c in contacts {
            if let [a, b] = c.body
                && a != NO_BODY
                && b != NO_BODY
            {
                self.sets.union(a, b);
            }
        }

        // Islands numbered in order of their first contact.
        self.island_of_root.clear();
        self.island_of_root.resize(body_count, NO_BODY);
        self.island_of_contact.clear();
        self.starts.clear();
        let mut counts = std::mem::take(&mut self.counts);
        counts.clear();
        for c in contacts {
            let any = if c.body[0] != NO_BODY {
                c.body[0]
            } else {
                c.body[1]
            };
            if any == NO_BODY {
                self.island_of_contact.push(NO_BODY);
                continue;
            }
            let root = self.sets.find(any) as usize;
            if self.island_of_root[root] == NO_BODY {
                self.island_of_root[root] = counts.len() as u32;
                counts.push(0);
            }
            let island = self.island_of_root[root];
            counts[island as usize] += 1;
            self.island_of_contact.push(island);
        }
        // Counting sort, stable, so each island lists its contacts in ascending order.
        self.starts.push(0);
        for &count in counts.iter() {
            let last = *self.starts.last().unwrap_or(&0);
            self.starts.push(last + count);
        }
        let total = *self.starts.last().unwrap_or(&0) as usize;
        self.order.clear();
        self.order.resize(total, 0);
        self.cursor.clear();
        self.cursor.extend_from_slice(&self.starts[..counts.len()]);
        self.counts = counts;
        for (i, &island) in self.island_of_contact.iter().enumerate() {
            if island != NO_BODY {
                let slot = &mut self.cursor[island as usize];
                self.order[*slot as usize] = i as u32;
                *slot += 1;
            }
        }

        self.build_adjacency(contacts, body_count);
    }

    fn build_adjacency(&mut self, contacts: &[PreparedContact], body_count: usize) {
        self.adj_starts.clear();
        self.adj_starts.resize(body_count + 1, 0);
        let sides = |c: &PreparedContact| {
            let [a, b] = c.body;
            // A degenerate self-contact is listed once.
            [a, if b == a { NO_BODY } else { b }]
        };
        for c in contacts {
            for body in sides(c) {
                if body != NO_BODY {
                    self.adj_starts[body as usize + 1] += 1;
                }
            }
        }
        for i in 0..body_count {
            self.adj_starts[i + 1] += self.adj_starts[i];
        }
        self.adj_contacts.clear();
        self.adj_contacts
            .resize(self.adj_starts[body_count] as usize, 0);
        self.cursor.clear();
        self.cursor
            .extend_from_slice(&self.adj_starts[..body_count]);
        for (i, c) in contacts.iter().enumerate() {
            for body in sides(c) {
                if body != NO_BODY {
                    let slot = &mut self.cursor[body as usize];
                    self.adj_contacts[*slot as usize] = i as u32;
                    *slot += 1;
                }
            }
        }
    }

    /// Number of islands.
    pub fn len(&self) -> usize {
        self.starts.len().saturating_sub(1)
    }

    /// Whether there is no island.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The contacts of island `i`, ascending.
    pub fn island(&self, i: usize) -> &[u32] {
        &self.order[self.starts[i] as usize..self.starts[i + 1] as usize]
    }

    /// The contacts touching moving body `body`, ascending (empty for `NO_BODY`).
    pub fn contacts_of(&self, body: u32) -> &[u32] {
        let b = body as usize;
        if body == NO_BODY || b + 1 >= self.adj_starts.len() {
            return &[];
        }
        &self.adj_contacts[self.adj_starts[b] as usize..self.adj_starts[b + 1] as usize]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn contact(a: u32, b: u32) -> PreparedContact {
        let mut p = PreparedContact::inert(0.0);
        p.body = [a, b];
        p
    }

    #[test]
    fn static_body_connects_nothing() {
        // Bodies 1 and 2 both rest on the static entry (NO_BODY side): two islands.
        // Body 3 touches 4; contact 4 touches 1 again.
        let contacts = [
            contact(1, NO_BODY),
            contact(NO_BODY, 2),
            contact(3, 4),
            contact(NO_BODY, NO_BODY),
            contact(4, 5),
            contact(1, NO_BODY),
        ];
        let mut islands = Islands::default();
        islands.build(&contacts, 6);
        assert_eq!(islands.len(), 3);
        assert_eq!(islands.island(0), &[0, 5]);
        assert_eq!(islands.island(1), &[1]);
        assert_eq!(islands.island(2), &[2, 4]);
        assert_eq!(islands.contacts_of(1), &[0, 5]);
        assert_eq!(islands.contacts_of(4), &[2, 4]);
        assert_eq!(islands.contacts_of(0), &[] as &[u32]);
        assert_eq!(islands.contacts_of(NO_BODY), &[] as &[u32]);
    }

    #[test]
    fn self_contact_is_listed_once() {
        let mut islands = Islands::default();
        islands.build(&[contact(2, 2)], 3);
        assert_eq!(islands.contacts_of(2), &[0]);
        assert_eq!(islands.island(0), &[0]);
    }
}
