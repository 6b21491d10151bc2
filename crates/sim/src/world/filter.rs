//! Link pairs that never collide (`physics.ignore_collisions`): a rapier contact-pair hook on
//! the colliders of the listed links. Adjacent links (joined by a joint) never collide
//! anyway; this is for the others a real robot's meshes make overlap (a hull filling a
//! gripper's gap, a cover over two links).

use std::collections::HashSet;

use rapier3d::prelude::{ActiveHooks, ColliderHandle, ColliderSet, PairFilterContext, PhysicsHooks, SolverFlags};

/// The collider pairs to skip, both orders.
#[derive(Debug, Clone, Default)]
pub(crate) struct PairFilter {
    pairs: HashSet<(ColliderHandle, ColliderHandle)>,
}

impl PairFilter {
    /// The filter for `links` pairs (URDF link indices), given each collider's link; turns on
    /// the hook of every collider it names.
    pub fn new(links: &[(usize, usize)], colliders: &[(usize, ColliderHandle)], set: &mut ColliderSet) -> Self {
        let mut pairs = HashSet::new();
        for &(a, b) in links {
            let of = |link: usize| colliders.iter().filter(move |(l, _)| *l == link).map(|(_, h)| *h);
            for ha in of(a) {
                for hb in of(b) {
                    pairs.insert((ha, hb));
                    pairs.insert((hb, ha));
                }
            }
        }
        for (h, _) in &pairs {
            if let Some(c) = set.get_mut(*h) {
                c.set_active_hooks(c.active_hooks() | ActiveHooks::FILTER_CONTACT_PAIRS);
            }
        }
        Self { pairs }
    }

    /// Whether there is nothing to filter (the world steps without hooks).
    pub fn is_empty(&self) -> bool {
        self.pairs.is_empty()
    }
}

impl PhysicsHooks for PairFilter {
    fn filter_contact_pair(&self, context: &PairFilterContext) -> Option<SolverFlags> {
        if self.pairs.contains(&(context.collider1, context.collider2)) {
            return None;
        }
        // rapier's own rule, which a hook replaces: no contacts between two non-dynamic bodies.
        let dynamic = |h: Option<rapier3d::prelude::RigidBodyHandle>| {
            h.and_then(|h| context.bodies.get(h)).is_some_and(|b| b.is_dynamic())
        };
        (dynamic(context.rigid_body1) || dynamic(context.rigid_body2)).then_some(SolverFlags::COMPUTE_RIGID_IMPULSES)
    }
}
