-- The affine (Voigt) bound of a bonded specimen's E and nu, from its file
-- (docs/potyondy-cundall.md): every bonded or touching pair of the core
-- (both balls 2 Rmax inside the surface; a pair with one ball outside at
-- half weight) as normal and shear springs along its branch vector, the
-- balls translating with the mean strain and not rotating; the isotropic
-- part of the stiffness tensor. No packing of those pairs is stiffer.
--   scripts/run docs/data/affine_bound.lua specimen.h5 rmax bond_kn_ks bond_modulus
local path, rmax, bond_ratio, ecbar = arg[1], tonumber(arg[2]), tonumber(arg[3]), tonumber(arg[4])
if not (path and rmax and bond_ratio and ecbar) then
  error("usage: affine_bound.lua specimen.h5 rmax bond_kn_ks bond_modulus")
end
local m = seixo.load(path)
m:cycle(1)
local d = m:dim()
local lo, hi = {}, {}
for k = 1, d do lo[k], hi[k] = math.huge, -math.huge end
for b in m:balls() do
  for k = 1, d do lo[k] = math.min(lo[k], b.pos[k] - b.radius); hi[k] = math.max(hi[k], b.pos[k] + b.radius) end
end
local cyl = d == 3
local cx, cy, R = 0.5 * (lo[1] + hi[1]), 0.5 * (lo[2] + hi[2]), 0.25 * (hi[1] - lo[1] + hi[2] - lo[2])
local function inside(p)
  if cyl then
    return math.sqrt((p[1] - cx) ^ 2 + (p[2] - cy) ^ 2) < R - 2 * rmax
      and p[3] > lo[3] + 2 * rmax and p[3] < hi[3] - 2 * rmax
  end
  return p[1] > lo[1] + 2 * rmax and p[1] < hi[1] - 2 * rmax and p[2] > lo[2] + 2 * rmax and p[2] < hi[2] - 2 * rmax
end
local V = cyl and math.pi * (R - 2 * rmax) ^ 2 * (hi[3] - lo[3] - 4 * rmax)
  or (hi[1] - lo[1] - 4 * rmax) * (hi[2] - lo[2] - 4 * rmax)
local C = {}
local function idx(i, j, k, l) return ((i * 3 + j) * 3 + k) * 3 + l end
for i = 0, 80 do C[i] = 0 end
local pairs_n, bonds_n, lin_n = 0, 0, 0
for c in m:contacts{kind = "ball-ball"} do
  -- a pair counts with half its weight when one ball is outside (its share of the volume)
  local wa, wb = inside(c.a.pos) and 0.5 or 0, inside(c.b.pos) and 0.5 or 0
  local w = wa + wb
  if w > 0 then
    local kn, ks = 0, 0
    if c.overlap > 0 then kn, ks = kn + c.kn, ks + c.ks; lin_n = lin_n + w end
    if c.bond == "parallel" or c.bond == "both" then
      local rb = c.pb_radius
      local area = d == 3 and math.pi * rb * rb or 2 * rb
      local knb = ecbar / (c.a.radius + c.b.radius) * area
      kn, ks = kn + knb, ks + knb / bond_ratio
      bonds_n = bonds_n + w
    end
    if kn > 0 then
      pairs_n = pairs_n + w
      local n = c.normal
      local l = {}
      local dist = 0
      for k = 1, d do l[k] = c.b.pos[k] - c.a.pos[k]; dist = dist + l[k] ^ 2 end
      for i = 1, d do for j = 1, d do for k = 1, d do for q = 1, d do
        local t = kn * n[i] * n[k] * l[j] * l[q] + ks * ((i == k and 1 or 0) - n[i] * n[k]) * l[j] * l[q]
        C[idx(i - 1, j - 1, k - 1, q - 1)] = C[idx(i - 1, j - 1, k - 1, q - 1)] + w * t / V
      end end end end
    end
  end
end
-- symmetric part on (ij) and (kl): sigma_ij = C_ijkl eps_kl
local function Cs(i, j, k, l)
  return 0.25 * (C[idx(i, j, k, l)] + C[idx(j, i, k, l)] + C[idx(i, j, l, k)] + C[idx(j, i, l, k)])
end
local A, B = 0, 0
for i = 0, d - 1 do for j = 0, d - 1 do A = A + Cs(i, i, j, j); B = B + Cs(i, j, i, j) end end
-- A = lambda d^2 + 2 mu d, B = lambda d + mu (d^2 + d)
local mu = (A - d * B) / (2 * d - d * (d * d + d))
local lambda = (A - 2 * mu * d) / (d * d)
local E, nu
if d == 3 then E, nu = mu * (3 * lambda + 2 * mu) / (lambda + mu), lambda / (2 * (lambda + mu))
else E, nu = 4 * mu * (lambda + mu) / (lambda + 2 * mu), lambda / (lambda + 2 * mu) end
print(string.format("%s: %dD core pairs %.0f (bonds %.0f, touching %.0f) in V %.4g: affine E %.4g GPa nu %.4f",
  path, d, pairs_n, bonds_n, lin_n, V, E / 1e9, nu))
