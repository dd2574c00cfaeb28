-- not-null keys, ratings in range, every rating's assignment and every assignment's worker and HIT known
select 'rating' as what, r.assignment_id as id from ratings r left join assignments a using (assignment_id)
where a.assignment_id is null or r.rating not between 1 and 5 or r.verb is null
union all
select 'assignment', a.assignment_id from assignments a left join workers w using (worker_id) left join hits h using (hit_id)
where w.worker_id is null or h.hit_id is null
