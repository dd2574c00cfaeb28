-- disagreement hot spots: frames whose raters disagree most
select verb, role1, arg1, role2, arg2, n, round(mean, 2) as mean, round(std, 2) as std,
       list(rating order by rating) as ratings
from frame_ratings
join valid_ratings using (verb, role1, arg1, role2, arg2)
where n >= 2
group by all
order by std desc, verb
limit 20
