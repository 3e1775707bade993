//! The binary encoding of the MD engine's state ([`MdState`]), its
//! grains and its neighbour list's ([`ListState`]), as a checkpoint's
//! engine field carries them after the fingerprint (`super::contract`).

use super::state::MdState;
use super::wall_springs::MeshEntry;
use crate::codec::{Dec, DecResult, Enc};
use crate::dim::Dim;
use crate::neighbors::ListState;
use crate::particles::{ParticleRecord, Particles};
use crate::rigid::bodies::Body;
use glam::DVec3;

/// Largest number of Gear derivative arrays a file may declare.
const MAX_GEAR: usize = 8;

/// Writes the grains, each with its Gear history.
pub fn encode_particles<D: Dim>(e: &mut Enc, p: &Particles<D>) {
    let n = p.len();
    e.len(n);
    e.len(p.gear.len());
    e.len(p.gear_ang.len());
    for i in 0..n {
        e.u64(p.id[i]);
        e.u32(p.kind[i]);
        e.bool(p.frozen[i]);
        for x in [
            p.radius[i],
            p.mass[i],
            p.inertia[i],
            p.inv_mass[i],
            p.inv_inertia[i],
        ] {
            e.f64(x);
        }
        e.vec::<D>(p.pos[i]);
        e.vec::<D>(p.vel[i]);
        e.vec::<D>(p.force[i]);
        e.ang::<D>(p.omega[i]);
        e.ang::<D>(p.torque[i]);
        p.gear.iter().for_each(|g| e.vec::<D>(g[i]));
        p.gear_ang.iter().for_each(|g| e.ang::<D>(g[i]));
    }
}

/// Reads the particle block written by [`encode_particles`].
pub fn decode_particles<D: Dim>(d: &mut Dec) -> DecResult<Particles<D>> {
    let per = 8 + 4 + 1 + 5 * 8 + 3 * 8 * D::D + 2 * 24;
    let n = d.len(per, "particle count")?;
    let ng = d.u64("gear orders")? as usize;
    let na = d.u64("angular gear orders")? as usize;
    if ng > MAX_GEAR || na > MAX_GEAR {
        return Err(format!(
            "{ng} and {na} Gear derivative arrays (at most {MAX_GEAR})"
        ));
    }
    let mut p = Particles::<D>::new();
    p.ensure_gear_history(ng, na);
    let (mut force, mut torque, mut inv_m, mut inv_i) = (
        Vec::with_capacity(n),
        Vec::with_capacity(n),
        Vec::with_capacity(n),
        Vec::with_capacity(n),
    );
    for _ in 0..n {
        let id = d.u64("particle id")?;
        let kind = d.u32("particle type")?;
        let frozen = d.bool("frozen flag")?;
        let radius = d.f64("radius")?;
        let mass = d.f64("mass")?;
        let inertia = d.f64("inertia")?;
        inv_m.push(d.f64("inverse mass")?);
        inv_i.push(d.f64("inverse inertia")?);
        let mut r = ParticleRecord::<D>::new(id, d.vec::<D>("position")?, radius, mass, inertia);
        r.kind = kind;
        r.frozen = frozen;
        r.vel = d.vec::<D>("velocity")?;
        force.push(d.vec::<D>("force")?);
        r.omega = d.ang::<D>("angular velocity")?;
        torque.push(d.ang::<D>("torque")?);
        for _ in 0..ng {
            r.gear.push(d.vec::<D>("Gear history")?);
        }
        for _ in 0..na {
            r.gear_ang.push(d.ang::<D>("angular Gear history")?);
        }
        p.push_record(r);
    }
    p.force = force;
    p.torque = torque;
    p.inv_mass = inv_m;
    p.inv_inertia = inv_i;
    Ok(p)
}

/// Writes the complete MD state.
pub fn encode_md<D: Dim>(e: &mut Enc, s: &MdState<D>) {
    e.f64(s.time);
    e.u64(s.step);
    encode_particles(e, &s.particles);
    let l = &s.list;
    e.len(l.pairs.len());
    for (p, &c) in l.pairs.iter().zip(&l.image) {
        e.u32(p[0]);
        e.u32(p[1]);
        e.u8(c);
    }
    e.vecs::<D>(&l.shifts);
    e.vecs::<D>(&l.ref_pos);
    e.u64(l.builds);
    e.bool(l.built);
    e.vecs::<D>(&s.springs);
    e.vecs::<D>(&s.wall_springs);
    e.vecs::<D>(&s.rolling);
    e.vecs::<D>(&s.wall_rolling);
    encode_mesh_springs::<D>(e, &s.mesh_springs);
    e.len(s.wall_loads.0.len());
    for load in &s.wall_loads.0 {
        for x in load.iter().flat_map(|v| v.to_array()) {
            e.f64(x);
        }
    }
    e.f64(s.wall_loads.1);
    e.u32(s.rebuilds_since_sort);
    e.u64(s.contacts);
    e.f64(s.max_overlap);
    e.f64(s.max_overlap_fraction);
    e.u64(s.worst_pair.0);
    match s.worst_pair.1 {
        Some(b) => {
            e.bool(true);
            e.u64(b);
        }
        None => e.bool(false),
    }
    // Last, so that an unsheared state's bytes are what they always were;
    // a fixed-pressure box and the servo walls' states (after a tag)
    // likewise.
    if let Some(offsets) = l.shear {
        offsets.iter().for_each(|&x| e.f64(x));
        if let Some(b) = s.pressure_box {
            b.iter().for_each(|&x| e.f64(x));
        }
    }
    if !s.servo.is_empty() {
        e.u64(SERVO_TAG);
        e.len(s.servo.len());
        s.servo.iter().flatten().for_each(|&x| e.f64(x));
    }
    if !s.bodies.is_empty() {
        e.u64(BODY_TAG);
        e.len(s.bodies.len());
        for b in &s.bodies {
            e.u32(b.shape);
            e.u64(b.first_id);
            let vectors = [b.pos, b.vel, b.ang_mom, b.force, b.torque];
            b.quat
                .into_iter()
                .chain(vectors.iter().flat_map(|v| v.to_array()))
                .for_each(|x| e.f64(x));
        }
    }
    if !s.mesh_rolling.is_empty() {
        e.u64(MESH_ROLLING_TAG);
        encode_mesh_springs::<D>(e, &s.mesh_rolling);
    }
}

/// Writes keyed mesh springs: their count, then (grain, wall, patch,
/// spring) each.
fn encode_mesh_springs<D: Dim>(e: &mut Enc, springs: &[MeshEntry<D::V>]) {
    e.len(springs.len());
    for &((g, w, patch), v) in springs {
        e.u32(g);
        e.u32(w);
        e.u32(patch);
        e.vec::<D>(v);
    }
}

/// Reads what [`encode_mesh_springs`] wrote; `what` names the springs
/// (and with "count", "grain", "wall", "patch" their parts) in errors.
fn decode_mesh_springs<D: Dim>(d: &mut Dec, what: &str) -> DecResult<Vec<MeshEntry<D::V>>> {
    let n = d.len(12 + 8 * D::D, &format!("{what} count"))?;
    let [grain, wall, patch] = ["grain", "wall", "patch"].map(|k| format!("{what} {k}"));
    let mut out = Vec::with_capacity(n);
    for _ in 0..n {
        let key = (d.u32(&grain)?, d.u32(&wall)?, d.u32(&patch)?);
        out.push((key, d.vec::<D>(what)?));
    }
    Ok(out)
}

/// Bytes of one body in the bodies' section.
const BODY_BYTES: usize = 4 + 8 + 19 * 8;

/// Reads the rigid bodies' section (after its tag).
fn decode_bodies(d: &mut Dec) -> DecResult<Vec<Body>> {
    let n = d.len(BODY_BYTES, "body count")?;
    let mut out = Vec::with_capacity(n);
    for _ in 0..n {
        let shape = d.u32("body shape")?;
        let first_id = d.u64("body's first grain id")?;
        let mut x = [0.0; 19];
        for v in &mut x {
            *v = d.f64("body state")?;
        }
        let v = |k: usize| DVec3::new(x[k], x[k + 1], x[k + 2]);
        out.push(Body {
            shape,
            first_id,
            quat: [x[0], x[1], x[2], x[3]],
            pos: v(4),
            vel: v(7),
            ang_mom: v(10),
            force: v(13),
            torque: v(16),
        });
    }
    Ok(out)
}

/// Opens the servo walls' section of a state. Read where a sheared box's
/// image offsets may begin too: as an f64 it is a NaN, which the first
/// offset (the shear's turns) never is.
const SERVO_TAG: u64 = 0x7ff8_5345_5256_4f00;

/// Opens the rigid bodies' section, after the servo walls' (a NaN too).
const BODY_TAG: u64 = 0x7ff8_424f_4459_5300;

/// Opens the mesh walls' rolling springs, after the bodies' (a NaN too).
const MESH_ROLLING_TAG: u64 = 0x7ff8_4d52_4f4c_4c00;

/// Reads the state written by [`encode_md`].
pub fn decode_md<D: Dim>(d: &mut Dec) -> DecResult<MdState<D>> {
    let time = d.f64("time")?;
    let step = d.u64("step")?;
    let particles = decode_particles::<D>(d)?;
    let np = d.len(9, "pair count")?;
    let (mut pairs, mut image) = (Vec::with_capacity(np), Vec::with_capacity(np));
    for _ in 0..np {
        pairs.push([d.u32("pair")?, d.u32("pair")?]);
        image.push(d.u8("image code")?);
    }
    let list = ListState {
        pairs,
        image,
        shifts: d.vecs::<D>("image shifts")?,
        ref_pos: d.vecs::<D>("skin reference positions")?,
        builds: d.u64("list builds")?,
        built: d.bool("list built flag")?,
        shear: None,
    };
    let springs = d.vecs::<D>("tangential springs")?;
    let wall_springs = d.vecs::<D>("wall springs")?;
    let rolling = d.vecs::<D>("rolling springs")?;
    let wall_rolling = d.vecs::<D>("wall rolling springs")?;
    let mesh_springs = decode_mesh_springs::<D>(d, "mesh spring")?;
    let nl = d.len(48, "wall load count")?;
    let mut loads = Vec::with_capacity(nl);
    for _ in 0..nl {
        let mut x = [0.0; 6];
        for v in &mut x {
            *v = d.f64("wall load")?;
        }
        loads.push([DVec3::new(x[0], x[1], x[2]), DVec3::new(x[3], x[4], x[5])]);
    }
    let wall_loads = (loads, d.f64("wall load time")?);
    let rebuilds_since_sort = d.u32("rebuild counter")?;
    let contacts = d.u64("contacts")?;
    let max_overlap = d.f64("max overlap")?;
    let max_overlap_fraction = d.f64("max overlap fraction")?;
    let worst_pair = (
        d.u64("worst pair")?,
        if d.bool("worst pair partner flag")? {
            Some(d.u64("worst pair partner")?)
        } else {
            None
        },
    );
    // A sheared box's image offsets, its fixed-pressure box, then the servo
    // walls' states close the state; each may be absent.
    let mut list = list;
    let mut pressure_box = None;
    let mut servo = Vec::new();
    let word = |d: &mut Dec, what| match d.remaining() {
        0 => Ok(None),
        _ => d.u64(what).map(Some),
    };
    // A section's tag, as an f64 a NaN: never a shear's turns or length.
    let untagged = |w: &u64| ![SERVO_TAG, BODY_TAG, MESH_ROLLING_TAG].contains(w);
    let mut next = word(d, "shear turns or section tag")?;
    if let Some(turns) = next.filter(untagged) {
        list.shear = Some([
            f64::from_bits(turns),
            d.f64("shear offset at build")?,
            d.f64("shear offset")?,
        ]);
        // A fixed-pressure box's length is finite, never the tag's NaN.
        next = word(d, "fixed-pressure box length or section tag")?;
        if let Some(length) = next.filter(untagged) {
            pressure_box = Some([
                f64::from_bits(length),
                d.f64("fixed-pressure box slide time")?,
                d.f64("fixed-pressure box slide offset")?,
            ]);
            next = word(d, "section tag")?;
        }
    }
    // Then tagged sections, each at most once and in this order.
    let mut bodies = Vec::new();
    let mut mesh_rolling = Vec::new();
    let mut order = [SERVO_TAG, BODY_TAG, MESH_ROLLING_TAG].iter();
    while let Some(tag) = next {
        if !order.any(|&t| t == tag) {
            return Err(format!(
                "unknown or misplaced section tag {tag:#018x} in the MD state (known: the \
                 servo walls' {SERVO_TAG:#018x}, the rigid bodies' {BODY_TAG:#018x}, the mesh \
                 rolling springs' {MESH_ROLLING_TAG:#018x}): a state of another engine version?"
            ));
        }
        if tag == SERVO_TAG {
            let ns = d.len(24, "servo wall count")?;
            for _ in 0..ns {
                servo.push([
                    d.f64("servo offset")?,
                    d.f64("servo speed")?,
                    d.f64("servo pressure")?,
                ]);
            }
        } else if tag == BODY_TAG {
            bodies = decode_bodies(d)?;
        } else {
            mesh_rolling = decode_mesh_springs::<D>(d, "mesh rolling spring")?;
        }
        next = word(d, "section tag")?;
    }
    Ok(MdState {
        time,
        step,
        particles,
        list,
        springs,
        wall_springs,
        rolling,
        wall_rolling,
        mesh_springs,
        mesh_rolling,
        wall_loads,
        servo,
        rebuilds_since_sort,
        contacts,
        max_overlap,
        max_overlap_fraction,
        worst_pair,
        pressure_box,
        bodies,
    })
}
