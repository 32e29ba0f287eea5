-- seixo.help: short documentation of every function, method and field,
-- behind the REPL's help():
--   help()              an overview
--   help(seixo), help(m), help(b), help(w), help(c)   what an object offers
--   help(m.cycle), help("cycle"), help("model:cycle"), help("ball.pos")
-- docs/lua-api.md is the full reference; tests/lua/help.lua checks that
-- both cover every name the bindings define.

local H = {}

-- name -> {signature, text}; units in brackets
local entries = {
  -- the module
  ["seixo.model"] = {"seixo.model{dim = 3, gravity = {0, 0, 0}, timestep = 0, timestep_safety = 0.8, skin = 0, overlap_limit = 0.5}",
    "A new model. dim 2 (disks of unit thickness) or 3 (spheres); gravity [m/s^2]; timestep [s], 0 = automatic; skin [m] of the broad phase, 0 = automatic; overlap_limit: the largest overlap a ball may be placed with, a fraction of its radius."},
  ["seixo.version"] = {"seixo.version", "The version string."},
  ["seixo.vec"] = {"seixo.vec(x, y[, z]) | seixo.vec{x, y[, z]} -> vector",
    "A vector with arithmetic (v + w, v - w, -v, v * s, s * v, v / s, v == w), fields x, y, z and methods dot, cross, norm, unit, copy; accepted wherever {x, y, z} is, and what b.pos, b.vel, w.force, ... return. A field's vector (b.pos) is a read-only copy: b.pos[1] = 5 is an error; set the whole field (local p = b.pos:copy(); p[1] = 5; b.pos = p)."},
  ["seixo.models"] = {"seixo.models() -> {model, ...}", "The open models, in the order they were made (a model no longer referenced may be collected)."},
  ["seixo.check_material"] = {"seixo.check_material({...}) -> true",
    "Checks a material table as m:material would (its keys, the core's ranges), without a model; raises m:material's error."},
  ["seixo.progress"] = {"seixo.progress([mode[, every]]) -> previous mode",
    "The progress of long cycles on stderr (steps, time, steps/s, ETA): false, true (a line rewritten in place: the default on a terminal) or 'log' (a plain line every `every` s, default 10: the default otherwise)."},
  ["seixo.clock"] = {"seixo.clock() -> seconds", "Wall-clock seconds from a monotonic clock: the difference of two readings times a run."},
  ["seixo.interrupts"] = {"seixo.interrupts() -> count", "How many interrupts (Ctrl-C, SIGUSR1; SIGTERM serially) came so far (under mpirun: those the ranks' cycles stopped on alike, and those a rank's own run answered): tells an interrupt from a failure caught by pcall."},
  ["seixo.threads"] = {"seixo.threads", "OpenMP threads for the step of each new model: --threads N (default 1); results do not depend on it."},
  ["seixo.optimize"] = {"seixo.optimize(f, {x0 =, lower =, upper =, algorithm = 'bobyqa', maxeval = 200, xtol = 1e-4, ftol = 0, stopval =, step =, seed = 1}) -> x, fmin, {evaluations =, status =}",
    "Minimises f(x) (x an array, f a number) within bounds by an NLopt derivative-free local algorithm: 'bobyqa', 'neldermead', 'sbplx' or 'cobyla'. xtol, ftol relative; an error in f stops the search and is raised."},
  ["seixo.cores"] = {"seixo.cores() -> n", "The processors online (lab.calibrate's default number of worker processes)."},
  ["seixo.executable"] = {"seixo.executable() -> path", "The path of the running seixo program, to start worker processes."},
  ["seixo.script"] = {"seixo.script([path]) -> path | nil", "The script the files written name as their provenance; a worker running a -e chunk for a script sets it (seixo.pool's workers take their parent's)."},
  ["seixo.rank"] = {"seixo.rank() -> r", "This process's MPI rank: 0 unless started by mpirun (and seixo built with MPI)."},
  ["seixo.ranks"] = {"seixo.ranks() -> n", "The number of MPI ranks: 1 unless started by mpirun -np N."},
  ["seixo.barrier"] = {"seixo.barrier()", "Every MPI rank waits until all are there (nothing serially): after " ..
                       "a shell command rank 0 ran alone, its files are there for every rank."},
  ["seixo.decompose"] = {"seixo.decompose([on]) -> on", "Whether models made from now on run their cycles decomposed over the MPI ranks (default true; lab.calibrate and lab.series turn it off while they run). Turning it on again is collective: the ranks settle the files each wrote meanwhile."},
  ["seixo.send"] = {"seixo.send(rank, text)", "Sends a string to another MPI rank (under mpirun only)."},
  ["seixo.receive"] = {"seixo.receive([wait = true]) -> text, rank", "The next string sent by any MPI rank and its sender; with wait = false, nil when none has come."},
  ["help"] = {"help([x])", "Help on x: a function, an object (model, ball, wall, contact), or a name such as \"cycle\" or \"ball.pos\"."},

  -- model: set-up
  ["model:material"] = {"m:material(name, {density =, kn =, ks =, friction =, damping =, ...}) -> name",
    "Defines or redefines a material. density [kg/m^3], kn, ks [N/m], friction, damping (local, in [0, 1)), viscous_normal, viscous_shear (critical-damping ratios), model = 'linear' | 'hertz' (shear_modulus [Pa], poisson), modulus [Pa] and stiffness_ratio (BPM), bond = {...} (bond micro-parameters)."},
  ["model:materials"] = {"m:materials() -> {name = {density =, kn =, ...}}", "Every material and its properties."},
  ["model:contact_model"] = {"m:contact_model{groups = {a, b} | materials = {a, b} | default = true | wall = w [, groups = a | materials = a], model =, material =, name =, ...} -> row",
    "A row of the contact-model table (PFC's CMAT): new ball-ball contacts of those groups or materials (or any other, default), or new contacts of wall w with balls of group a, material a or any, take the row's law and parameters, read as m:material reads them, and keep them while they last."},
  ["model:contact_models"] = {"m:contact_models() -> {{...}, ...}", "The contact-model table's rows in order."},
  ["model:ball"] = {"m:ball{pos =, radius =, vel =, spin =, material =, group =} -> ball;  m:ball(id) -> ball | nil",
    "Adds a ball (pos [m], radius [m], vel [m/s], spin [rad/s]), or finds one by id."},
  ["model:balls"] = {"m:balls([filter]) -> iterator", "for b in m:balls() do ... end; filter = {group =, region =, where = fn}. Iterates over a snapshot."},
  ["model:ball_count"] = {"m:ball_count() -> n", "Number of balls."},
  ["model:wall"] = {"m:wall{kind = 'plane' | 'line' | 'rect' | 'segment' | 'cylinder' | 'mesh' | 'box', ...} -> wall (a box: array of walls);  m:wall(id) -> wall | nil",
    "Adds a wall: plane/line {point, normal}, rect {corner, edge1, edge2}, segment {p1, p2}, cylinder {point, axis, radius, height, radial_vel}, mesh {file = 'x.stl' | triangles [, vertices], point, spin, repair}, box {min, max}; kn, ks [N/m], friction, vel [m/s]. Or finds one by id."},
  ["model:walls"] = {"m:walls() -> iterator", "for w in m:walls() do ... end"},
  ["model:wall_count"] = {"m:wall_count() -> n", "Number of walls."},
  ["model:generate"] = {"m:generate{region =, radius =, count = | porosity =, method =, seed =, ...} -> n, porosity",
    "Generates balls in a region: method 'random' (non-overlapping), 'distribute' (overlapping to a porosity, then relaxed), 'expand' (radius expansion to a porosity), 'lattice' (packing = square|hex|cubic|fcc). radius = r or {rmin, rmax} [m]; distribution 'uniform' | 'normal' | 'lognormal' (mean, std), or psd = {{r, fraction of the volume passing}, ...} (a grading curve); material, group, tries, relax = {steps, ratio, calm}. With template = name: clumps at random orientations, scale = s or {smin, smax} in place of radius (method 'random')."},
  ["model:close"] = {"m:close()", "Frees the model now; any later use is an error."},
  ["model:summary"] = {"m:summary() -> text", "The summary print(m) shows."},

  -- model: time and cycling
  ["model:cycle"] = {"m:cycle(n)", "Takes n steps, running callbacks and histories. Ctrl-C stops it at a step boundary (error 'interrupted at step N')."},
  ["model:solve"] = {"m:solve{ratio =, steps =, time =, every = 100} -> reason, ratio, steps",
    "Cycles until the mean unbalanced-force ratio <= ratio (checked every `every` steps), or `steps` steps, or `time` [s] of model time; reason is 'ratio', 'steps' or 'time'. With no limit: ratio = 1e-5."},
  ["model:on"] = {"m:on(point, fn[, {every = N}]) -> id",
    "Calls fn(m) at step boundaries s with s % N == 0: point 'after' (alias 'cycle') once step s is taken, 'before' before step s + 1. Events: m:on('bond_break' | 'contact_create' | 'contact_delete' | 'ball_leave_region', fn(m, e)[, {region =}]) after the step they happen in."},
  ["model:off"] = {"m:off(id) -> removed", "Removes a callback or an event handler added by m:on."},
  ["model:dim"] = {"m:dim() -> 2 | 3", "The model's dimension."},
  ["model:time"] = {"m:time() -> t", "Model time [s]."},
  ["model:step"] = {"m:step() -> n", "Steps taken."},
  ["model:timestep"] = {"m:timestep() -> dt", "The timestep the next step uses [s]."},
  ["model:set_timestep"] = {"m:set_timestep(dt | 'auto')", "Fixes the timestep [s], or returns to the automatic one (no argument, 0 or 'auto')."},
  ["model:critical_timestep"] = {"m:critical_timestep() -> dt", "The critical timestep estimate sqrt(m/k), without the safety factor [s]."},
  ["model:gravity"] = {"m:gravity() -> g", "Gravity [m/s^2]."},
  ["model:set_gravity"] = {"m:set_gravity(g)", "Sets gravity [m/s^2]."},
  ["model:ratio"] = {"m:ratio() -> r", "PFC's mean unbalanced-force ratio: mean |F + m g| over the mean contact force."},
  ["model:energy"] = {"m:energy() -> {kinetic =, gravitational =, strain =, ...}", "Energies [J]; accumulated terms (slip, local_damping, viscous, boundary_work, bond_released) need m:track_energy(true)."},
  ["model:contact_count"] = {"m:contact_count() -> n", "Contacts of the last step."},
  ["model:contacts"] = {"m:contacts([{ball =, wall =, kind =}]) -> iterator", "for c in m:contacts() do ... end over a snapshot of the last step's contacts."},
  ["model:ranks"] = {"m:ranks() -> n", "The number of MPI ranks its cycles are decomposed over (1: serial); results are bit-identical to a serial run."},
  ["model:hash"] = {"m:hash() -> hex", "A hash of the full state: equal hashes, bit-identical states."},
  ["model:bytes"] = {"m:bytes() -> n", "Memory held by the model [bytes]."},
  ["model:memory"] = {"m:memory() -> {total =, peak =, balls =, contacts =, bonds =, work =, per_ball =, per_contact =, ...}",
    "Where the model's bytes are: ball arrays, contact store, bonds, working storage; bytes per ball and per contact."},
  ["model:profile"] = {"m:profile([{print = true, reset = false}]) -> {broad_phase = {seconds =, calls =}, ..., total =}",
    "Wall-clock time per stage of the step (broad phase, ball contacts, wall contacts, integration, callbacks, other) since the model was created or reset; prints the table unless print = false."},

  -- model: groups and bulk operations
  ["model:group"] = {"m:group(name, filter | fn[, slot]) -> n", "Puts the selected balls (filter {group, slot, region, where} or a predicate fn(ball)) in the group, in group slot `slot` (1 to 8, default 1: b.group); returns how many. A filter's group matches any slot, or the filter's slot."},
  ["model:groups"] = {"m:groups() -> {name = count}", "Every group and its number of balls."},
  ["model:set"] = {"m:set{group =, region =, where =, vel =, spin =, applied_force =, applied_moment =, radius =, damping =, material =, fix =} -> n",
    "Sets fields of the selected balls at once (in C); returns how many."},
  ["model:sum"] = {"m:sum(field[, filter]) -> value", "Sum of a ball field over the selection: pos, vel, spin, force, moment, applied_force, applied_moment, radius, mass, inertia, damping, volume, speed, kinetic."},
  ["model:mean"] = {"m:mean(field[, filter]) -> value | nil", "Mean of a ball field over the selection (nil when empty)."},
  ["model:min"] = {"m:min(field[, filter]) -> value | nil", "Smallest value (per component) over the selection."},
  ["model:max"] = {"m:max(field[, filter]) -> value | nil", "Largest value (per component) over the selection."},
  ["model:count"] = {"m:count([filter]) -> n", "Number of selected balls (a region selects by centre)."},
  ["model:remove_balls"] = {"m:remove_balls(filter) -> n", "Removes the selected balls (queued while a callback runs)."},

  -- model: histories
  ["model:history"] = {"m:history(name, source[, {every = N}]);  m:history(name) -> {steps, times, values}",
    "Records a time series every N steps: source a function(m) -> number, a builtin (time, step, timestep, ratio, contacts, balls, kinetic, gravitational, strain, ...), or {ball = b | wall = w, field =, component =}. Saved with the model; a loaded history of a function is detached until m:history(name, fn) gives it again."},
  ["model:histories"] = {"m:histories() -> names", "The histories' names."},
  ["model:history_remove"] = {"m:history_remove(name)", "Stops and forgets a history."},
  ["model:history_csv"] = {"m:history_csv(path[, names])", "Writes step, time and the histories as CSV (names quoted as needed; a unique temporary name, fsync, rename)."},

  -- model: bonds
  ["model:bond"] = {"m:bond{kind = 'parallel' | 'contact' | 'flatjoint', gap =, seed =, materials =, ...} -> n", "Installs bonds between balls closer than gap [m]."},
  ["model:flatjoint"] = {"m:flatjoint(a, b) -> {{state, area, centroid, gap, fn, fs, tensile_strength, cohesion}, ...} | nil", "The elements of the flat joint between balls a and b."},
  ["model:joint"] = {"m:joint{point =, normal = | dip = [, dip_direction =], kn =, ks =, friction =, dilation =, tension =, cohesion =, friction_angle =, radius_multiplier =, radius =} -> number, bonds, contacts", "Adds a smooth joint: contacts and bonds across the plane (or, with radius, across its disk about point) take the smooth-joint law."},
  ["model:joints"] = {"m:joints() -> {{point, normal, kn, ks, ...}, ...}", "The model's smooth joints as given."},
  ["model:flatjoint_unbond"] = {"m:flatjoint_unbond(a, b, e)", "Makes element e of the flat joint between a and b a slit (compression and friction only)."},
  ["model:bond_count"] = {"m:bond_count() -> n", "Intact bonds."},
  ["model:cracks"] = {"m:cracks() -> {{time, step, pos, mode, kind, a, b, fn, fs, mn, ms}, ...}", "The log of broken bonds."},
  ["model:crack_count"] = {"m:crack_count([mode]) -> n", "Broken bonds, all or of mode 'tension' | 'shear'."},
  ["model:track_energy"] = {"m:track_energy(on)", "Starts (from zero) or stops accumulating dissipated energies and boundary work."},

  -- model: files (src/lua/io.c)
  ["model:save"] = {"m:save(path[, {compression = 0..9}]) -> skipped",
    "Writes the whole model to an HDF5 snapshot that restarts bit-for-bit, with m:vars(), groups, extras, histories and seeds; returns the paths of values it could not save."},
  ["model:vars"] = {"m:vars() -> table", "The user's variables: plain data kept with the model and saved by m:save."},
  ["model:output"] = {"m:output{path =, every =, fields =, compression =, append =} -> output",
    "Writes the model now and every `every` steps to an HDF5 series with an .xmf for ParaView; the histories grow in it as the run goes."},
  ["seixo.replaceable"] = {"seixo.replaceable(path) -> true | false, why", "Whether a file written to path may replace what is there: files are written under a temporary name and renamed over the old one, so a symbolic link, a device such as /dev/null, a pipe or a folder at path is refused (m:save, outputs, histories and the lab library's files)."},
  ["seixo.load"] = {"seixo.load(path[, {dim = 2 | 3}]) -> model", "Reads a snapshot written by m:save (histories recording on); callbacks, outputs and history functions are registered again by the script."},
  ["seixo.xdmf"] = {"seixo.xdmf(path)", "Rebuilds the .xmf file of an output series."},
  ["output:write"] = {"o:write()", "Writes the model to the series now."},
  ["output:close"] = {"o:close()", "Stops the output and closes its file."},
  ["output:count"] = {"o:count() -> n", "Snapshots written."},
  ["output:path"] = {"o:path() -> path", "The series' file."},

  -- periodic space (src/lua/periodic.c)
  ["model:periodic"] = {"m:periodic{min =, max =, axes = \"xyz\", tilt = {xy =, xz =, yz =}}; m:periodic(false); m:periodic() -> {min =, max =, size =, axes =, tilt =} | nil",
    "Makes space periodic on the given axes (a ball leaving one face comes back at the other; balls touch the images across the faces); tilt [m] shears the cell into a parallelepiped; false: open space again; no argument: the cell now."},
  ["model:cell_control"] = {"m:cell_control{xx = {rate =} | {stress =}, yy =, zz =, xy =, xz =, yz =, alpha = 0.5, max_rate = 1}; m:cell_control() -> table",
    "Drives the periodic cell (every axis periodic): per component a strain rate [1/s] or a servo on the cell's stress [Pa], compression positive; no argument: the control now."},
  ["model:cell_stress"] = {"m:cell_stress() -> stress, volume",
    "The periodic cell's average stress tensor [Pa] (compression positive, Love-Weber over every contact, through the boundary) and its volume [m^3]."},

  -- laboratory tests (src/lua/lab.c)
  ["model:measure"] = {"m:measure(region) -> {stress =, fabric =, porosity =, coordination =, balls =, contacts =, volume =, solid =}",
    "Measures in a box, sphere (3D) or disk (2D) region: the average stress tensor [Pa] (compression positive), the fabric tensor, porosity, coordination number."},
  ["wall:servo"] = {"w:servo{target =, area =, alpha = 0.5, max_speed = 1}; w:servo(nil)",
    "Puts the wall under servo control: its normal velocity follows G (stress - target), its velocity along the wall kept, target [Pa] on area [m^2] (2D: m, unit thickness), speed bounded by max_speed [m/s]; call again to update area; nil releases it."},
  ["wall:load"] = {"w:load() -> force, contacts, kn", "The servo's inputs after the last step: total normal contact force [N], contact count, mean contact kn [N/m]."},
  ["wall:radius"] = {"w:radius() -> radius, radial_vel", "A cylinder's radius [m] and its rate of change [m/s]."},
  ["wall:set_radial_vel"] = {"w:set_radial_vel(v)", "Sets a cylinder's radial velocity [m/s] (> 0 expands)."},
  ["wall:set_radius"] = {"w:set_radius(r)", "Sets a cylinder's radius [m] (> 0)."},

  -- ball
  ["ball:remove"] = {"b:remove()", "Removes the ball (queued while a callback runs)."},
  ["ball:set_group"] = {"b:set_group(name | nil, slot)", "Puts the ball in a group in one of its 8 group slots (PFC's slots; slot 1 is b.group)."},
  ["ball.groups"] = {"b.groups", "The ball's groups by slot: {[slot] = name} (read-only; slot 1 is b.group)."},
  ["ball:set_extra"] = {"b:set_extra(key, value)", "Stores a user value with the ball (same as b.extra[key] = value)."},
  ["ball:get_extra"] = {"b:get_extra(key[, default]) -> value", "A user value stored with the ball."},
  ["ball.id"] = {"b.id", "The ball's stable id (read-only)."},
  ["ball.pos"] = {"b.pos", "Position [m]."},
  ["ball.disp"] = {"b.disp", "Displacement since m:reset_disp() [m] (read-only); a ball added later is measured from its first cycle."},
  ["model:reset_disp"] = {"m:reset_disp([filter]) -> n", "Makes the selected balls' (all: every ball's) positions the reference of b.disp; returns how many."},
  ["ball.vel"] = {"b.vel", "Velocity [m/s]."},
  ["ball.spin"] = {"b.spin", "Angular velocity [rad/s] (2D: a number, about z)."},
  ["ball.force"] = {"b.force", "Contact plus applied force of the last step [N] (read-only)."},
  ["ball.moment"] = {"b.moment", "Contact plus applied moment of the last step [N m] (read-only; 2D: a number)."},
  ["ball.applied_force"] = {"b.applied_force", "A constant external force added every step [N]."},
  ["ball.applied_moment"] = {"b.applied_moment", "A constant external moment added every step [N m]."},
  ["ball.radius"] = {"b.radius", "Radius [m]; mass and inertia follow the density."},
  ["ball.mass"] = {"b.mass", "Mass [kg] (read-only)."},
  ["ball.inertia"] = {"b.inertia", "Moment of inertia [kg m^2] (read-only)."},
  ["ball.material"] = {"b.material", "The material's name."},
  ["ball.fix"] = {"b.fix", "Fixed velocity components: {'vx', 'vy', 'vz', 'wx', 'wy', 'wz'}, or 'vel', 'spin', 'all'; nil or {} frees them."},
  ["ball.damping"] = {"b.damping", "Local damping coefficient in [0, 1)."},
  ["ball.group"] = {"b.group", "The group's name, or nil."},
  ["ball.extra"] = {"b.extra", "A table of user values kept with the ball: b.extra.tag = 1."},
  ["ball.clump"] = {"b.clump", "The clump a pebble belongs to, nil for a free ball (read-only)."},

  -- clumps (src/lua/clumps.c)
  ["model:clump_template"] = {"m:clump_template(name, pebbles | path[, {lines =}]) -> info;  m:clump_template(name) -> info | nil",
    "Defines a clump template from pebbles {{x, y[, z], r}, ...} (or {pos =, radius =}) or a file of spheres (x y [z] r per line, # comments); returns {name, pebbles, volume, centroid, inertia, principal, axes, overlapping, error} per unit density."},
  ["model:clump_templates"] = {"m:clump_templates() -> {name = info}", "Every clump template and its properties."},
  ["model:clump"] = {"m:clump{template =, pos =, orientation =, scale = 1, vel =, spin =, material =, group =} -> clump;  m:clump(id) -> clump | nil",
    "Adds a clump (a rigid body of its template's pebbles) with its centroid at pos [m]; orientation {w, x, y, z} or {axis =, angle =} (2D: an angle [rad]); or finds one by id."},
  ["model:clumps"] = {"m:clumps() -> iterator", "for c in m:clumps() do ... end over a snapshot of the clumps."},
  ["model:clump_count"] = {"m:clump_count() -> n", "Number of clumps."},
  ["clump:remove"] = {"cl:remove()", "Removes the clump and its pebbles (not inside a callback)."},
  ["clump.id"] = {"cl.id", "The clump's stable id (its own numbering, apart from balls')."},
  ["clump.pos"] = {"cl.pos", "Centroid [m] (writable: moves the clump)."},
  ["clump.vel"] = {"cl.vel", "Velocity of the centroid [m/s]."},
  ["clump.spin"] = {"cl.spin", "Angular velocity in space [rad/s] (2D: a number)."},
  ["clump.orientation"] = {"cl.orientation", "Unit quaternion {w, x, y, z} from the template frame to space (2D: the angle [rad]); writable."},
  ["clump.force"] = {"cl.force", "Resultant of its pebbles' contact and applied forces of the last step [N] (read-only)."},
  ["clump.moment"] = {"cl.moment", "Their moment about the centroid [N m] (read-only)."},
  ["clump.angular_momentum"] = {"cl.angular_momentum", "Angular momentum about the centroid, in space [kg m^2/s] (read-only)."},
  ["clump.mass"] = {"cl.mass", "Mass [kg] (read-only)."},
  ["clump.volume"] = {"cl.volume", "Volume of the union of its pebbles [m^3] (2D: [m^2])."},
  ["clump.inertia"] = {"cl.inertia", "Inertia tensor about the centroid in space axes [kg m^2] (2D: Izz, a number)."},
  ["clump.principal"] = {"cl.principal", "Principal moments, ascending [kg m^2] (2D: a number)."},
  ["clump.scale"] = {"cl.scale", "Its template's scale (read-only)."},
  ["clump.template"] = {"cl.template", "Its template's name (read-only)."},
  ["clump.material"] = {"cl.material", "The material of the body and its pebbles; its density gives the mass."},
  ["clump.damping"] = {"cl.damping", "Local damping coefficient in [0, 1)."},
  ["clump.fix"] = {"cl.fix", "Fixed components like b.fix; in 3D the spin is fixed as a whole ('spin') or not."},
  ["clump.pebbles"] = {"cl.pebbles", "Its pebbles, an array of balls in template order (read-only)."},

  -- wall
  ["wall:remove"] = {"w:remove()", "Removes the wall (queued while a callback runs)."},
  ["wall:set_extra"] = {"w:set_extra(key, value)", "Stores a user value with the wall (same as w.extra[key] = value)."},
  ["wall:get_extra"] = {"w:get_extra(key[, default]) -> value", "A user value stored with the wall."},
  ["wall.id"] = {"w.id", "The wall's stable id."},
  ["wall.kind"] = {"w.kind", "'plane', 'line', 'rect', 'segment', 'cylinder' or 'mesh'."},
  ["wall.force"] = {"w.force", "Resultant force of the balls on the wall in the last step [N]."},
  ["wall.moment"] = {"w.moment", "Its moment about the wall's reference point [N m]."},
  ["wall.vel"] = {"w.vel", "Imposed velocity [m/s] (writable)."},
  ["wall.point"] = {"w.point", "Plane/line: a point on it; rect: its corner; segment: its first end; cylinder: its axis point; mesh: the point it turns about [m] (writable: moves the wall)."},
  ["wall.spin"] = {"w.spin", "Mesh: angular velocity about its point [rad/s] (writable)."},
  ["wall.vertices"] = {"w.vertices", "Mesh: its vertices where they are now, {x, y, z} each [m]."},
  ["wall.triangles"] = {"w.triangles", "Mesh: its facets, three 1-based vertex numbers each."},
  ["wall.vertex_count"] = {"w.vertex_count", "Mesh: its number of vertices (welded)."},
  ["wall.facet_count"] = {"w.facet_count", "Mesh: its number of facets (after repair)."},
  ["wall.normal"] = {"w.normal", "Plane/line: the unit normal towards the balls; rect, segment: their normal; nil for a cylinder or a mesh."},
  ["wall.axis"] = {"w.axis", "Cylinder: the unit axis; nil for other kinds."},
  ["wall.edge1"] = {"w.edge1", "Rect: first edge; segment: second end minus first [m]; nil for other kinds."},
  ["wall.edge2"] = {"w.edge2", "Rect: second edge [m]; nil for other kinds."},
  ["wall.kn"] = {"w.kn", "Normal stiffness [N/m] (writable, > 0); a material's wall: its material's; rigid: inf."},
  ["wall.ks"] = {"w.ks", "Shear stiffness [N/m] (writable, >= 0); a material's wall: its material's; rigid: inf."},
  ["wall.friction"] = {"w.friction", "Friction coefficient (writable, >= 0)."},
  ["wall.material"] = {"w.material", "The wall's own material by name, or nil (writable): it replaces kn, ks and friction."},
  ["wall.rigid"] = {"w.rigid", "true: the wall does not deform (writable): a Hertz ball meets the rigid plane E* = E/(1-nu^2)."},
  ["wall.extra"] = {"w.extra", "A table of user values kept with the wall: w.extra.tag = 1."},

  -- contact
  ["contact.a"] = {"c.a", "The first entity: a ball."},
  ["contact.b"] = {"c.b", "The second entity: a ball or a wall."},
  ["contact.kind"] = {"c.kind", "'ball-ball' or 'ball-wall'."},
  ["contact.normal"] = {"c.normal", "Unit normal from a to b."},
  ["contact.point"] = {"c.point", "Contact point [m]."},
  ["contact.overlap"] = {"c.overlap", "Overlap [m] (> 0 when touching)."},
  ["contact.fn"] = {"c.fn", "Normal force [N], compression positive."},
  ["contact.fs"] = {"c.fs", "Shear force on b [N]."},
  ["contact.force"] = {"c.force", "Total contact force on b [N] (a feels the opposite)."},
  ["contact.kn"] = {"c.kn", "Normal stiffness [N/m]."},
  ["contact.ks"] = {"c.ks", "Shear stiffness [N/m]."},
  ["contact.bond"] = {"c.bond", "nil, 'contact', 'parallel', 'both', 'flatjoint' or 'smoothjoint' (a bonded smooth joint)."},
  ["contact.pb_fn"] = {"c.pb_fn", "Parallel-bond normal force [N], compression positive."},
  ["contact.pb_fs"] = {"c.pb_fs", "Parallel-bond shear force on b [N]."},
  ["contact.pb_moment"] = {"c.pb_moment", "Parallel-bond moment on b [N m]."},
  ["contact.pb_radius"] = {"c.pb_radius", "Parallel-bond radius [m]."},
  ["contact.contact_model"] = {"c.contact_model", "The contact-model row the contact took when it was created (m:contact_model), nil for its materials' law."},
  ["contact.joint"] = {"c.joint", "The smooth joint (m:joint's number) whose law the contact takes, or nil."},
  ["contact.shift"] = {"c.shift", "Periodic space: the period [m] b is seen through (its image at b.pos + shift touches a); zeros inside the cell."},

  -- seixo.util
  ["util.add"] = {"util.add(a, b)", "a + b"},
  ["util.sub"] = {"util.sub(a, b)", "a - b"},
  ["util.scale"] = {"util.scale(a, s)", "s a"},
  ["util.dot"] = {"util.dot(a, b)", "a . b"},
  ["util.cross"] = {"util.cross(a, b)", "a x b (2D: the z component)"},
  ["util.norm"] = {"util.norm(a)", "|a|"},
  ["util.dist"] = {"util.dist(a, b)", "|a - b|"},
  ["util.normalize"] = {"util.normalize(a)", "a / |a|"},
  ["util.lerp"] = {"util.lerp(a, b, t)", "a + t (b - a)"},
  ["util.mean_sd"] = {"util.mean_sd(xs) -> mean, sd", "the mean and sample standard deviation of a list of numbers"},
  ["util.show"] = {"util.show(v[, depth[, limit]]) -> text", "A readable text of any value: tables to depth levels (4), each cut after limit entries (none); the REPL prints tables with it."},
  ["util.print"] = {"util.print(...)", "Prints values with util.show."},
  ["util.read_csv"] = {"util.read_csv(path) -> {header, columns, rows}", "Reads a CSV written by m:history_csv."},

  -- seixo.lab (lua/seixo/lab.lua and its parts in lua/seixo/lab/)
  ["lab.rock"] = {"lab.rock([over]) -> material", "Bonded-particle micro-parameters of a granite-like rock (Potyondy & Cundall 2004, seed 4.4), with the fields of over replacing the defaults; over.dim = 3 starts from the set calibrated in 3D (Ec = 87 GPa, bonds 227 +- 52 MPa), 2 or none from P&C's PFC2D set."},
  ["lab.specimen"] = {"lab.specimen{dim =, shape = 'cylinder' | 'prism' | 'disk', diameter =, height =, path =, material =, ...} -> spec",
    "Material genesis of a bonded specimen (radius expansion, servo to an isotropic stress, bonds, relaxation, trimming), saved to path [m, Pa]."},
  ["lab.open"] = {"lab.open(path) -> spec", "The specimen saved at path by lab.specimen."},
  ["lab.triaxial"] = {"lab.triaxial(spec, {confining =, strain_rate =, target_ratio = 2e-3, max_rate =, density_scale = 1, out =, ...}) -> result",
    "A triaxial test at confining = sigma3 [Pa] held by servo-controlled walls (0: unconfined); returns peak [Pa], E [Pa], nu, cracks, curves. The platens speed up from strain_rate to max_rate [1/s] (default 8 x strain_rate) while the unbalanced-force ratio stays under target_ratio/2 and no bond breaks, and slow down when it exceeds target_ratio or bonds break (target_ratio = false: a constant rate); density_scale >= 1 multiplies the balls' density (timestep x sqrt)."},
  ["lab.ucs"] = {"lab.ucs(spec[, opts]) -> result", "The unconfined compression test (lab.triaxial without confinement)."},
  ["lab.lateral_strain"] = {"lab.lateral_strain(m[, axis]) -> strain",
    "strain() returns the lateral strain since the call (compression positive): the affine fit of the balls' motion across axis (default the last), without a ball squeezed out of the assembly."},
  ["lab.brazilian"] = {"lab.brazilian(spec[, opts]) -> result", "The Brazilian test of a disk: two platens close; sigma_t = 2 F / (pi D t) [Pa] at the peak (tensile_strength) and at the split (split: the halves parted)."},
  ["lab.mohr_coulomb"] = {"lab.mohr_coulomb({{sigma3, sigma1}, ...}) -> {c =, phi =, N =, intercept =, r2 =, rms =, points =}",
    "The Mohr-Coulomb fit of failure states [Pa]; phi in degrees."},
  ["lab.series"] = {"lab.series(spec, {confining = {sigma3, ...}, jobs =, quasi_static =, out =, ...}) -> results",
    "A UCS and triaxial tests at each sigma3 [Pa], the Mohr-Coulomb fit of their peaks and the plots (out: a file prefix); the tests run in jobs processes at once (default: the cores; same results bit for bit); quasi_static = true or a tolerance: the first test again at half the rate."},
  ["lab.calibrate"] = {"lab.calibrate{targets =, parameters =, specimen =, material =, seeds =, workers =, out =, ...} -> result",
    "Finds micro-parameters whose lab tests reproduce target macro-properties (E, nu, UCS, BTS, c, phi or a stress-strain curve): the BPM's scalings, then NLopt's BOBYQA; seeds' mean and scatter; worker processes or MPI ranks; resumes from its log (out)."},
  ["lab.periodic"] = {"lab.periodic (require \"seixo.periodic\")",
    "Laboratory tests on a periodic cell, without walls: periodic.specimen{...}, periodic.triaxial(spec, {...}), periodic.shear(spec, {...}) (see docs/lua-api.md, lab.periodic)."},
  ["lab.write_csv"] = {"lab.write_csv(path, header, rows)", "Writes rows (arrays of numbers; nil: empty) under a header to a CSV file, atomically; names quoted as needed; a ragged row or a cell that is no number is an error."},
  ["plot.live"] = {"plot.live(m, names[, {every = 1000, terminal =, output =, title =, x = 'step' | 'time', log =}]) -> plot",
    "A gnuplot plot of histories of m, redrawn every `every` steps while m cycles (p:draw() now, p:close() stops it); the run's bits do not change."},
  ["lab.have_gnuplot"] = {"lab.have_gnuplot() -> bool", "Whether gnuplot can be run (the plots are skipped, with a note, if not)."},
}
H.entries = entries

-- The classes, from the metatables the bindings registered.
local classes = {model = "seixo.model", ball = "seixo.ball", wall = "seixo.wall", contact = "seixo.contact",
                 output = "seixo.output", clump = "seixo.clump"}

local function class_of(x)
  local mt = getmetatable(x)
  if type(mt) ~= "table" then return nil end
  for kind, tname in pairs(classes) do
    if mt.__name == tname then return kind, mt end
  end
end

local function registry_class(kind)
  local reg = debug.getregistry()
  return reg[classes[kind]]
end

-- The entry names of a function value, by identity.
local function name_of_function(fn)
  for kind in pairs(classes) do
    local mt = registry_class(kind)
    if mt and mt.__methods then
      for name, f in pairs(mt.__methods) do
        if f == fn then return kind .. ":" .. name end
      end
    end
  end
  local seixo = package.loaded.seixo
  if seixo then
    for name, f in pairs(seixo) do
      if f == fn then return "seixo." .. name end
    end
  end
  for prefix, module in pairs{util = "seixo.util", lab = "seixo.lab", plot = "seixo.plot"} do
    for name, f in pairs(package.loaded[module] or {}) do
      if f == fn then return prefix .. "." .. name end
    end
  end
  if fn == rawget(_G, "help") then return "help" end
end

local function sorted(t)
  table.sort(t)
  return t
end

local function entry_text(name)
  local e = entries[name]
  if not e then return nil end
  return e[1] .. "\n  " .. e[2]
end

-- One line per name: "  name  text" (text cut to fit).
local function listing(title, names)
  local out = {title}
  for _, name in ipairs(names) do
    local e = entries[name]
    local text = e and e[2] or "(undocumented)"
    if #text > 64 then text = text:sub(1, 61) .. "..." end
    out[#out + 1] = string.format("  %-22s %s", name:match("[:%.]([%w_]+)$") or name, text)
  end
  return table.concat(out, "\n")
end

local function members(prefix)
  local names = {}
  for name in pairs(entries) do
    if name:sub(1, #prefix) == prefix then names[#names + 1] = name end
  end
  return sorted(names)
end

local letters = {clump = "cl"} -- where the first letter is another class's (c: contact)

local function object_text(kind)
  local parts = {}
  local letter = letters[kind] or kind:sub(1, 1)
  local methods = members(kind .. ":")
  if #methods > 0 then parts[#parts + 1] = listing(kind .. " methods (" .. letter .. ":name(...)):", methods) end
  local fields = members(kind .. ".")
  if #fields > 0 then parts[#parts + 1] = listing(kind .. " fields (" .. letter .. ".name):", fields) end
  return table.concat(parts, "\n")
end

local overview = [[
seixo: a DEM simulator driven from Lua.
  local m = seixo.model{dim = 3, gravity = {0, 0, -9.81}}
  m:material("glass", {density = 2500, kn = 1e6, ks = 1e6, friction = 0.5, damping = 0.7,
                       viscous_normal = 0.3, rolling_friction = 0.1})  -- a 3D bed settles with rolling resistance
  m:wall{kind = "box", min = {0, 0, 0}, max = {0.12, 0.12, 0.3}}
  m:generate{count = 300, radius = {4e-3, 6e-3}, region = {box = {{0, 0, 0}, {0.12, 0.12, 0.1}}}, seed = 7}
  m:history("ke", "kinetic", {every = 100})
  print(m:solve{ratio = 1e-3, steps = 300000})  -- why it stopped, the ratio, the steps: some 10 s
  print(m)
help(m) lists the model's methods, help(b) a ball's fields, help("solve") one entry;
help("util") the vector helpers of require "seixo.util", help("lab") the laboratory tests
of require "seixo.lab", help("plot") live plots of histories. Top-level locals of a line, or of a script run with -i, stay
defined for the next lines; seixo.models() lists the open models.
The full reference: docs/lua-api.md.]]

--- The help text of x (see the top of this file).
function H.text(x)
  if x == nil then return overview end
  if type(x) == "function" then
    local name = name_of_function(x)
    return name and entry_text(name) or "no help for this function"
  end
  if x == package.loaded.seixo then return listing("seixo:", members("seixo.")) end
  if x == package.loaded["seixo.util"] then return listing("seixo.util (require \"seixo.util\"):", members("util.")) end
  if x == package.loaded["seixo.lab"] then return listing("seixo.lab (require \"seixo.lab\"):", members("lab.")) end
  if x == package.loaded["seixo.plot"] then return listing("seixo.plot (require \"seixo.plot\"):", members("plot.")) end
  local kind = class_of(x)
  if kind then return object_text(kind) end
  if type(x) ~= "string" then return "no help for a " .. type(x) .. "; try help()" end
  if entries[x] then return entry_text(x) end
  if classes[x] then return object_text(x) end
  if x == "seixo" then return listing("seixo:", members("seixo.")) end
  if x == "util" then return listing("seixo.util (require \"seixo.util\"):", members("util.")) end
  if x == "lab" then return listing("seixo.lab (require \"seixo.lab\"):", members("lab.")) end
  if x == "plot" then return listing("seixo.plot (require \"seixo.plot\"):", members("plot.")) end
  -- a bare name: every entry it ends
  local found = {}
  for name in pairs(entries) do
    if name:match("[:%.]([%w_]+)$") == x then found[#found + 1] = name end
  end
  if #found == 0 then return "no help for '" .. x .. "'; try help()" end
  sorted(found)
  local out = {}
  for i, name in ipairs(found) do out[i] = entry_text(name) end
  return table.concat(out, "\n")
end

--- Prints the help text of x.
function H.help(x)
  print(H.text(x))
end

return H
