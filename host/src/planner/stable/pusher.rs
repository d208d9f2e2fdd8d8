//! Pushers and the pushes they can make: Lynch & Mason (1996) §4.4 (Figs. 13–15: the
//! omnidirectional mobile robot, and the car-like robot whose feasible rotation centres lie on
//! its rear axle at least a minimum turning radius away, forward only) and §4.4 (Figs. 16–18: a
//! robot arm of negligible extent), plus this project's differential-drive robot with a flat
//! front plate (rotation centres anywhere on its wheel axle).
//!
//! The usable pushes are the stable set intersected with what the pusher can do (Fig. 14).
//! A pusher is described in the *contact frame* of an edge: x along the edge, y along the inward
//! normal (the robot's forward direction); the pusher's front touches the edge at `x = offset`.

use crate::mechanics::stable::StableSet;
use crate::mechanics::{LineContact, MechanicsError, Slider, V2, V3};

/// What kind of pusher pushes.
#[derive(Debug, Clone, PartialEq)]
pub enum PusherKind {
    /// A robot arm that can lift and re-place its pusher anywhere (§4.4, Figs. 16–18);
    /// negligible extent in the plane, contact changes need no transit path.
    Arm,
    /// An omnidirectional mobile robot (Fig. 13): any stable push.
    Omni,
    /// A car-like robot (Figs. 14–15): rotation centres on the rear axle, `min_turning_radius`
    /// or more from the robot's centre line, forward only; straight ahead included.
    Car {
        /// Minimum turning radius (m).
        min_turning_radius: f64,
    },
    /// A differential-drive robot with a flat front plate: rotation centres anywhere on the
    /// wheel axle (it can turn in place), forward pushes only.
    DiffDrive,
}

/// A pusher: its kind, its footprint and where its axle is.
#[derive(Debug, Clone, PartialEq)]
pub struct Pusher {
    /// The kind.
    pub kind: PusherKind,
    /// Footprint as a convex polygon in the pusher frame (front plate on `y = 0`, body at
    /// `y < 0`, centre line `x = 0`); empty for a pusher of negligible extent.
    pub footprint: Vec<V2>,
    /// Width of the flat front plate; the line contact is the part of the edge it covers.
    /// `None`: longer than any edge.
    pub plate_width: Option<f64>,
    /// Distance from the front plate back to the wheel axle (car, differential drive).
    pub axle_offset: f64,
}

impl Pusher {
    /// A car's minimum turning radius, m; `None` for other kinds.
    pub fn min_turning_radius(&self) -> Option<f64> {
        match self.kind {
            PusherKind::Car { min_turning_radius } => Some(min_turning_radius),
            _ => None,
        }
    }

    /// A pusher of negligible extent, as the robot arm of §4.4.
    pub fn arm() -> Self {
        Pusher {
            kind: PusherKind::Arm,
            footprint: vec![],
            plate_width: None,
            axle_offset: 0.0,
        }
    }

    /// A box-shaped mobile robot `width × depth` behind its front plate.
    pub fn boxed(
        kind: PusherKind,
        width: f64,
        depth: f64,
        axle_offset: f64,
        plate_width: Option<f64>,
    ) -> Self {
        let w = width / 2.0;
        let footprint = vec![
            V2::new(-w, -depth),
            V2::new(w, -depth),
            V2::new(w, 0.0),
            V2::new(-w, 0.0),
        ];
        Pusher {
            kind,
            footprint,
            plate_width,
            axle_offset,
        }
    }

    /// Whether contact changes need a transit path in the plane (§4.6): every mobile robot.
    pub fn is_mobile(&self) -> bool {
        !matches!(self.kind, PusherKind::Arm)
    }

    /// Radius of the disk about the pusher's centre line at the axle that holds the footprint
    /// (the robot's swept disk when turning in place).
    pub fn turning_radius_disk(&self) -> f64 {
        let c = V2::new(0.0, -self.axle_offset);
        self.footprint
            .iter()
            .map(|p| (p - c).norm())
            .fold(0.0, f64::max)
    }

    /// Where the pusher sits on edge `edge`: the contact-frame x of its centre line (the foot of
    /// the perpendicular from the centre of friction, clamped into what of the slider lies on
    /// the edge's line), and the line contact its plate makes there: the true contact, from the
    /// outermost to the outermost point of the slider the plate covers on that line (for a
    /// concave slider this may span several collinear edges and the gaps between them, as a
    /// line contact is equivalent to two point contacts at its ends, §3.3).
    pub fn placement(&self, slider: &Slider, edge: usize) -> Result<Placement, MechanicsError> {
        let full = LineContact::full_edge(slider, edge)?;
        let (xa, xb) = (
            full.to_contact_frame(full.a).x,
            full.to_contact_frame(full.b).x,
        );
        let y0 = full.to_contact_frame(full.a).y;
        // What of the slider lies on the edge's line: the edge itself, and for a concave slider
        // every other edge on the same hull line (a U's two prongs). A plate on the edge
        // touches all of them that it covers; the true contact runs between the outermost.
        let n_v = slider.vertices.len();
        let tol = 1e-9 * (1.0 + slider.radius());
        let on_line: Vec<(f64, f64)> = (0..n_v)
            .filter_map(|j| {
                let (p, q) = (
                    full.to_contact_frame(slider.vertices[j]),
                    full.to_contact_frame(slider.vertices[(j + 1) % n_v]),
                );
                ((p.y - y0).abs() <= tol && (q.y - y0).abs() <= tol)
                    .then_some((p.x.min(q.x), p.x.max(q.x)))
            })
            .collect();
        let touched = |lo: f64, hi: f64| {
            on_line.iter().filter(|(a, b)| *a <= hi && *b >= lo).fold(
                None,
                |acc: Option<(f64, f64)>, (a, b)| {
                    let (a, b) = (a.max(lo), b.min(hi));
                    Some(acc.map_or((a, b), |(c, d)| (c.min(a), d.max(b))))
                },
            )
        };
        let span_lo = on_line.iter().map(|s| s.0).fold(f64::INFINITY, f64::min);
        let span_hi = on_line
            .iter()
            .map(|s| s.1)
            .fold(f64::NEG_INFINITY, f64::max);
        let plate = |offset: f64| match self.plate_width {
            Some(w) => touched(offset - w / 2.0, offset + w / 2.0),
            None => touched(f64::NEG_INFINITY, f64::INFINITY),
        };
        // Centred under the centre of friction where the plate touches there, else on the edge.
        let centred = 0.0f64.clamp(span_lo.min(span_hi), span_hi.max(span_lo));
        let on_edge = 0.0f64.clamp(xa.min(xb), xa.max(xb));
        let (offset, (lo, hi)) = match plate(centred) {
            Some(c) if c.1 > c.0 => (centred, c),
            _ => (on_edge, plate(on_edge).unwrap_or((xa.min(xb), xa.max(xb)))),
        };
        let t = full.tangent();
        let n = full.normal();
        let contact = LineContact {
            edge,
            a: t * lo + n * y0,
            b: t * hi + n * y0,
        };
        Ok(Placement {
            contact,
            offset,
            y0,
            origin: t * offset + n * y0,
            tangent: t,
            normal: n,
        })
    }

    /// Extra constraints (rows `a·v ≥ 0`, contact frame) that the pusher's kinematics impose;
    /// equalities appear as two opposite rows.
    fn kinematic_rows(&self, pl: &Placement) -> Vec<V3> {
        let y_axle = pl.y0 - self.axle_offset;
        let x_r = pl.offset;
        match &self.kind {
            PusherKind::Arm | PusherKind::Omni => vec![],
            // Rotation about (c_x, y_axle): v_x = ω y_axle. Forward: the robot's centre point
            // moves with v_y + ω x_r > 0; turning radius |c_x − x_r| ≥ R.
            PusherKind::Car {
                min_turning_radius: r,
            } => vec![
                V3::new(1.0, 0.0, -y_axle),
                V3::new(-1.0, 0.0, y_axle),
                V3::new(0.0, 1.0, x_r - r),
                V3::new(0.0, 1.0, x_r + r),
            ],
            PusherKind::DiffDrive => vec![
                V3::new(1.0, 0.0, -y_axle),
                V3::new(-1.0, 0.0, y_axle),
                V3::new(0.0, 1.0, x_r),
            ],
        }
    }

    /// The usable pushes: the stable set of the placement's contact intersected with the
    /// pusher's feasible velocity directions. For a car or a differential drive the straight
    /// push is added to the controls when it is usable (as §4.4 advises, to smooth paths).
    pub fn usable(&self, stable: &StableSet, pl: &Placement) -> Usable {
        let rows: Vec<V3> = self
            .kinematic_rows(pl)
            .iter()
            .map(|r| pl.contact.twist_to_slider(*r))
            .collect();
        let set = stable.intersect(&rows);
        let mut controls = set.extremal.clone();
        if !rows.is_empty() {
            let straight = pl.contact.twist_to_slider(V3::new(0.0, 1.0, 0.0));
            if set.contains(&straight) && !controls.iter().any(|c| (c - straight).norm() < 1e-7) {
                controls.push(straight);
            }
        }
        Usable { set, controls }
    }
}

/// The pusher placed on one edge.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Placement {
    /// The line contact of the plate with the edge.
    pub contact: LineContact,
    /// Contact-frame x of the pusher's centre line.
    pub offset: f64,
    /// Contact-frame y of the edge (negative: distance of the edge from the centre of friction).
    pub y0: f64,
    /// Slider-frame position of the pusher frame's origin (centre of the plate).
    pub origin: V2,
    /// Slider-frame x axis of the pusher frame (along the edge).
    pub tangent: V2,
    /// Slider-frame y axis of the pusher frame (forward, into the slider).
    pub normal: V2,
}

impl Placement {
    /// A pusher-frame point in the slider frame.
    pub fn to_slider(&self, p: V2) -> V2 {
        self.origin + self.tangent * p.x + self.normal * p.y
    }
}

/// The usable pushes of one contact.
#[derive(Debug, Clone, PartialEq)]
pub struct Usable {
    /// Stable set ∩ pusher's feasible set.
    pub set: StableSet,
    /// The planner's controls: the extremal directions of `set` (plus straight ahead for
    /// wheeled robots).
    pub controls: Vec<V3>,
}
